//! The exported functions: pointer checks, the opaque objects' storage,
//! and nothing else (the work is in `planner` and `autopilot`).
//!
//! An opaque object is a byte array of fixed size and 8-byte alignment
//! (`AUVNAV_PLANNER_SIZE`, `AUVNAV_AUTOPILOT_SIZE`, asserted below against
//! the Rust types). It starts with a `u32` marker that `*_init` writes
//! after the object is fully built; every other call checks it first, so
//! a zeroed (static) object that was never initialized, or whose
//! initialization failed, is `AUVNAV_ERR_NOT_INITIALIZED`.

use core::ffi::c_char;
use core::mem::{MaybeUninit, align_of, size_of};
use core::ptr::{addr_of, addr_of_mut};

use crate::autopilot::AutopilotInner;
use crate::error::{self, AUVNAV_ERR_CAPACITY, AUVNAV_ERR_NOT_INITIALIZED, AUVNAV_ERR_NULL};
use crate::error::{AUVNAV_ERR_NON_FINITE, AUVNAV_OK};
use crate::planner::PlannerInner;
use crate::types::*;

/// Bytes of an `auvnav_planner`.
pub const AUVNAV_PLANNER_SIZE: usize = 45056;
/// Bytes of an `auvnav_autopilot`.
pub const AUVNAV_AUTOPILOT_SIZE: usize = 128;
/// Alignment of both opaque objects, bytes.
pub const AUVNAV_OBJECT_ALIGN: usize = 8;

/// The planner: opaque, place it statically (`static auvnav_planner p;`).
#[repr(C)]
#[allow(non_camel_case_types)]
pub union auvnav_planner {
    /// The storage.
    pub opaque: [u8; AUVNAV_PLANNER_SIZE],
    /// Aligns the storage to 8 bytes.
    pub align: u64,
}

/// The autopilot: opaque, place it statically.
#[repr(C)]
#[allow(non_camel_case_types)]
pub union auvnav_autopilot {
    /// The storage.
    pub opaque: [u8; AUVNAV_AUTOPILOT_SIZE],
    /// Aligns the storage to 8 bytes.
    pub align: u64,
}

/// The marker of an initialized planner.
const PLANNER_READY: u32 = 0x4155_5650;
/// The marker of an initialized autopilot.
const AUTOPILOT_READY: u32 = 0x4155_5641;

/// What an opaque object holds: the marker, then the object.
#[repr(C)]
struct Slot<T> {
    ready: u32,
    inner: MaybeUninit<T>,
}

const _: () = {
    assert!(size_of::<Slot<PlannerInner>>() <= AUVNAV_PLANNER_SIZE);
    assert!(align_of::<Slot<PlannerInner>>() <= AUVNAV_OBJECT_ALIGN);
    assert!(size_of::<Slot<AutopilotInner>>() <= AUVNAV_AUTOPILOT_SIZE);
    assert!(align_of::<Slot<AutopilotInner>>() <= AUVNAV_OBJECT_ALIGN);
    assert!(size_of::<auvnav_planner>() == AUVNAV_PLANNER_SIZE);
    assert!(align_of::<auvnav_planner>() == AUVNAV_OBJECT_ALIGN);
    assert!(size_of::<auvnav_autopilot>() == AUVNAV_AUTOPILOT_SIZE);
    assert!(align_of::<auvnav_autopilot>() == AUVNAV_OBJECT_ALIGN);
};

/// The initialized object in `slot`, if its marker says so.
///
/// # Safety
/// `slot` is null or points to a live object of the opaque type's size
/// and alignment (the C caller's contract), not used elsewhere during the
/// call.
unsafe fn ready<'a, T>(slot: *mut Slot<T>, marker: u32) -> Result<&'a mut T, i32> {
    if slot.is_null() {
        return Err(AUVNAV_ERR_NULL);
    }
    // SAFETY: non-null and, by the caller's contract, valid for reads of
    // the whole object, whose first word is the marker.
    let flag = unsafe { addr_of!((*slot).ready).read() };
    if flag != marker {
        return Err(AUVNAV_ERR_NOT_INITIALIZED);
    }
    // SAFETY: the marker is written only after `inner` was fully
    // initialized (`install`), and cleared before it is replaced.
    Ok(unsafe { (*addr_of_mut!((*slot).inner)).assume_init_mut() })
}

/// The initialized object in `slot`, read only, if its marker says so.
///
/// # Safety
/// As [`ready`], for reads only.
unsafe fn ready_ref<'a, T>(slot: *const Slot<T>, marker: u32) -> Result<&'a T, i32> {
    if slot.is_null() {
        return Err(AUVNAV_ERR_NULL);
    }
    // SAFETY: non-null and valid for reads (caller's contract).
    let flag = unsafe { addr_of!((*slot).ready).read() };
    if flag != marker {
        return Err(AUVNAV_ERR_NOT_INITIALIZED);
    }
    // SAFETY: the marker says `inner` is fully initialized (`install`).
    Ok(unsafe { (*addr_of!((*slot).inner)).assume_init_ref() })
}

/// Builds the object with `make` and installs it in `slot`.
///
/// # Safety
/// As [`ready`].
unsafe fn install<T>(
    slot: *mut Slot<T>,
    marker: u32,
    make: impl FnOnce() -> Result<T, i32>,
) -> i32 {
    if slot.is_null() {
        return AUVNAV_ERR_NULL;
    }
    // SAFETY: `slot` is valid for writes (caller's contract). The marker
    // is cleared first: a failed init leaves an uninitialized object.
    unsafe { addr_of_mut!((*slot).ready).write(0) };
    match make() {
        Ok(inner) => {
            // SAFETY: valid for writes; the previous object, if any, is
            // plain data (no destructor to run).
            unsafe {
                addr_of_mut!((*slot).inner).write(MaybeUninit::new(inner));
                addr_of_mut!((*slot).ready).write(marker);
            }
            AUVNAV_OK
        }
        Err(code) => code,
    }
}

/// A reference to `*p`, or `AUVNAV_ERR_NULL`.
///
/// # Safety
/// `p` is null or points to a valid, initialized `T` (the C caller's
/// contract for every struct argument).
unsafe fn arg<'a, T>(p: *const T) -> Result<&'a T, i32> {
    // SAFETY: the caller's contract.
    unsafe { p.as_ref() }.ok_or(AUVNAV_ERR_NULL)
}

/// A slice of `n` floats at `p`: `AUVNAV_ERR_CAPACITY` over `cap` (checked
/// before the memory is touched), `AUVNAV_ERR_NULL` for a null `p`.
///
/// # Safety
/// `p` is null or points to at least `n` floats when `n <= cap`.
unsafe fn floats<'a>(p: *const f32, n: u32, cap: u32) -> Result<&'a [f32], i32> {
    if n > cap {
        return Err(AUVNAV_ERR_CAPACITY);
    }
    if p.is_null() {
        return Err(AUVNAV_ERR_NULL);
    }
    let n = usize::try_from(n).map_err(|_| AUVNAV_ERR_CAPACITY)?;
    // SAFETY: non-null, `n` floats readable (caller's contract), and the
    // library only reads them during this call.
    Ok(unsafe { core::slice::from_raw_parts(p, n) })
}

/// Folds a result into a return code.
fn code(r: Result<(), i32>) -> i32 {
    r.err().unwrap_or(AUVNAV_OK)
}

/// Writes `value` to `out` if it is not null.
///
/// # Safety
/// `out` is null or valid for a write of `T`.
unsafe fn put<T>(out: *mut T, value: T) {
    // SAFETY: the caller's contract.
    if let Some(o) = unsafe { out.as_mut() } {
        *o = value;
    }
}

/// Writes the paper's vehicle, C-AUV #4 (model.md section 9), to `out`
/// (nothing for a null `out`).
///
/// # Safety
/// `out` is null or valid for writing an `auvnav_vehicle`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_vehicle_default(out: *mut auvnav_vehicle) {
    // SAFETY: the caller's contract.
    unsafe { put(out, crate::convert::vehicle_default()) }
}

/// Writes the default mission: `h_r` 80 m, `h_a` 60 m, depths [0, 6000]
/// m, no uncertainty (nothing for a null `out`).
///
/// # Safety
/// `out` is null or valid for writing an `auvnav_mission`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_mission_default(out: *mut auvnav_mission) {
    // SAFETY: the caller's contract.
    unsafe { put(out, crate::convert::mission_default()) }
}

/// Writes the library's `PlannerConfig::default()`: horizon mode, BFGS,
/// horizon `AUVNAV_MAX_HORIZON`, 200 iterations, no flight budget
/// (nothing for a null `out`).
///
/// # Safety
/// `out` is null or valid for writing an `auvnav_settings`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_settings_default(out: *mut auvnav_settings) {
    // SAFETY: the caller's contract.
    unsafe { put(out, crate::convert::settings_default()) }
}

/// Initializes the planner for vehicle `v`, mission `m` and settings `s`
/// (copied; no line yet). On an error the planner is left uninitialized.
/// Validates the vehicle, its stability check included (about 4 M
/// instructions on a Cortex-M4F): call it at start-up, not in the loop.
///
/// # Safety
/// Each pointer is null or valid: `p` for an `auvnav_planner` (any
/// content), the others for reading their struct.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_planner_init(
    p: *mut auvnav_planner,
    v: *const auvnav_vehicle,
    m: *const auvnav_mission,
    s: *const auvnav_settings,
) -> i32 {
    // SAFETY: the caller's contract for `v`, `m`, `s`, checked for null.
    let args = unsafe { (arg(v), arg(m), arg(s)) };
    let (Ok(v), Ok(m), Ok(s)) = args else {
        return AUVNAV_ERR_NULL;
    };
    // SAFETY: `p` is null or a valid `auvnav_planner` (caller's contract),
    // whose size and alignment hold a `Slot<PlannerInner>` (asserted).
    unsafe { install(p.cast(), PLANNER_READY, || PlannerInner::new(v, m, s)) }
}

/// Copies the line in: `n_samples` bottom samples (`x` strictly
/// increasing, m; `bottom` depths, m) and `n_waypoints` waypoint positions
/// (m), and puts the vehicle at waypoint 0 in trimmed level flight at
/// `initial_depth` (m; NAN: the default `b(X_0) - h_r`). On an error the
/// planner has no line (`auvnav_plan_next` returns `AUVNAV_ERR_NO_LINE`).
///
/// # Safety
/// `p` is null or a valid planner; `x`, `bottom` are null or point to
/// `n_samples` floats, `waypoints` to `n_waypoints` floats (when within
/// the capacities).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_planner_set_line(
    p: *mut auvnav_planner,
    x: *const f32,
    bottom: *const f32,
    n_samples: u32,
    waypoints: *const f32,
    n_waypoints: u32,
    initial_depth: f32,
) -> i32 {
    // SAFETY: the caller's contract for `p`.
    let planner = match unsafe { ready::<PlannerInner>(p.cast(), PLANNER_READY) } {
        Ok(planner) => planner,
        Err(e) => return e,
    };
    // SAFETY: the caller's contract for the arrays and their lengths.
    let arrays = unsafe {
        (
            floats(x, n_samples, AUVNAV_MAX_SAMPLES),
            floats(bottom, n_samples, AUVNAV_MAX_SAMPLES),
            floats(waypoints, n_waypoints, AUVNAV_MAX_WAYPOINTS),
        )
    };
    match arrays {
        (Ok(x), Ok(b), Ok(w)) => code(planner.set_line((x, b), w, initial_depth)),
        (Err(e), _, _) | (_, Err(e), _) | (_, _, Err(e)) => e,
    }
}

/// Plans the next track from the held state, writes the plan to `out`
/// and advances the held state to the predicted state at the next
/// waypoint. On an error `out` is not written and the planner does not
/// advance.
///
/// # Safety
/// `p` is null or a valid planner; `out` is null or valid for writing an
/// `auvnav_plan`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_plan_next(p: *mut auvnav_planner, out: *mut auvnav_plan) -> i32 {
    // SAFETY: the caller's contract for `p`.
    let planner = match unsafe { ready::<PlannerInner>(p.cast(), PLANNER_READY) } {
        Ok(planner) => planner,
        Err(e) => return e,
    };
    // SAFETY: the caller's contract for `out`.
    let Some(out) = (unsafe { out.as_mut() }) else {
        return AUVNAV_ERR_NULL;
    };
    match planner.plan_next() {
        Ok(plan) => {
            *out = plan;
            AUVNAV_OK
        }
        Err(e) => e,
    }
}

/// Flies the next track at reference depth `depth` (m), a depth the
/// planner did not plan (the climb after `AUVNAV_ERR_BELOW_BOTTOM`, an
/// operator's override), carrying the declared worlds through it, and
/// advances to the track after it: the next `auvnav_plan_next` certifies
/// from the worlds' spread, as the `plan` tool does after its climb.
///
/// # Safety
/// `p` is null or a valid planner.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_planner_carry(p: *mut auvnav_planner, depth: f32) -> i32 {
    // SAFETY: the caller's contract for `p`.
    let planner = match unsafe { ready::<PlannerInner>(p.cast(), PLANNER_READY) } {
        Ok(planner) => planner,
        Err(e) => return e,
    };
    code(planner.carry(depth))
}

/// Replaces the held state by what the vehicle measured (the rest of the
/// model state kept from the prediction), for the next
/// `auvnav_plan_next`.
///
/// # Safety
/// `p` is null or a valid planner; `m` null or a valid measurement.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_planner_measured(
    p: *mut auvnav_planner,
    m: *const auvnav_measurement,
) -> i32 {
    // SAFETY: the caller's contract for `p`.
    let planner = match unsafe { ready::<PlannerInner>(p.cast(), PLANNER_READY) } {
        Ok(planner) => planner,
        Err(e) => return e,
    };
    // SAFETY: the caller's contract for `m`.
    match unsafe { arg(m) } {
        Ok(m) => code(planner.measured(m)),
        Err(e) => e,
    }
}

/// The next track to plan, 1-based (0 for a null or uninitialized
/// planner).
///
/// # Safety
/// `p` is null or a valid planner.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_planner_track(p: *const auvnav_planner) -> u32 {
    // SAFETY: the caller's contract; only read.
    match unsafe { ready_ref::<PlannerInner>(p.cast(), PLANNER_READY) } {
        Ok(planner) => planner.track(),
        Err(_) => 0,
    }
}

/// Initializes the autopilot: the same depth → pitch → elevator cascade
/// the planner simulates, for vehicle `v`, engaged bumplessly from a zero
/// elevator. On an error the autopilot is left uninitialized. Validates
/// the vehicle as `auvnav_planner_init` does (about 4 M instructions).
///
/// # Safety
/// `a` is null or valid for an `auvnav_autopilot`; `v` null or valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_autopilot_init(
    a: *mut auvnav_autopilot,
    v: *const auvnav_vehicle,
) -> i32 {
    // SAFETY: the caller's contract for `v`.
    let Ok(v) = (unsafe { arg(v) }) else {
        return AUVNAV_ERR_NULL;
    };
    // SAFETY: `a` is null or a valid `auvnav_autopilot` (caller's
    // contract), whose size and alignment hold the slot (asserted).
    unsafe { install(a.cast(), AUTOPILOT_READY, || AutopilotInner::new(v)) }
}

/// One autopilot sample (call once per sample time): reference depth and
/// depth (m), pitch (deg), pitch rate (deg/s); writes the elevator (deg).
/// Returns `AUVNAV_OK`, or `AUVNAV_ERR_NON_FINITE` when an input is NaN
/// or infinite: then `*elevator_out` is still written, with the last
/// command held, the integrators are frozen, and the next finite sample
/// re-engages bumplessly (the command continues from the held one).
///
/// # Safety
/// `a` is null or a valid autopilot; `elevator_out` null or valid for a
/// write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_autopilot_step(
    a: *mut auvnav_autopilot,
    reference_depth: f32,
    depth: f32,
    pitch: f32,
    pitch_rate: f32,
    elevator_out: *mut f32,
) -> i32 {
    // SAFETY: the caller's contract for `a`.
    let ap = match unsafe { ready::<AutopilotInner>(a.cast(), AUTOPILOT_READY) } {
        Ok(ap) => ap,
        Err(e) => return e,
    };
    // SAFETY: the caller's contract for `elevator_out`.
    let Some(out) = (unsafe { elevator_out.as_mut() }) else {
        return AUVNAV_ERR_NULL;
    };
    let s = ap.step(reference_depth, depth, pitch, pitch_rate);
    *out = s.elevator;
    if s.non_finite {
        AUVNAV_ERR_NON_FINITE
    } else {
        AUVNAV_OK
    }
}

/// Hold input: while `hold` is true, `auvnav_autopilot_step` outputs the
/// last command and freezes the integrators; the first step after it is
/// released re-engages bumplessly.
///
/// # Safety
/// `a` is null or a valid autopilot.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_autopilot_hold(a: *mut auvnav_autopilot, hold: bool) -> i32 {
    // SAFETY: the caller's contract for `a`.
    match unsafe { ready::<AutopilotInner>(a.cast(), AUTOPILOT_READY) } {
        Ok(ap) => {
            ap.set_hold(hold);
            AUVNAV_OK
        }
        Err(e) => e,
    }
}

/// Bumpless reset: take over a vehicle whose elevator stands at
/// `elevator` deg (finite); the next step's command continues from it.
///
/// # Safety
/// `a` is null or a valid autopilot.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn auvnav_autopilot_engage(a: *mut auvnav_autopilot, elevator: f32) -> i32 {
    // SAFETY: the caller's contract for `a`.
    let ap = match unsafe { ready::<AutopilotInner>(a.cast(), AUTOPILOT_READY) } {
        Ok(ap) => ap,
        Err(e) => return e,
    };
    if !elevator.is_finite() {
        return AUVNAV_ERR_NON_FINITE;
    }
    ap.engage(elevator);
    AUVNAV_OK
}

/// The static, NUL-terminated name of `code` (`"AUVNAV_OK"`,
/// `"AUVNAV_ERR_NULL"`, ...; `"AUVNAV_ERR_UNKNOWN"` for any other value).
#[unsafe(no_mangle)]
pub extern "C" fn auvnav_error_name(code: i32) -> *const c_char {
    error::name(code).as_ptr().cast()
}
