//! Panic-freedom proof: the planner linked with `panic-never`.
//!
//! `panic-never`'s panic handler refers to a symbol that does not exist, so
//! this example only links if the optimizer removed every panicking branch
//! of everything it uses: the whole planner (`Planner::plan` with the mode,
//! method and settings hidden from the optimizer behind `black_box`, so no
//! branch is folded away), the simulation, the gradient, the optimizers,
//! the profile and the constructors. Build it in release (opt-level 3; the
//! check gives false alarms without optimization):
//!
//! ```sh
//! cargo build --release --target thumbv7em-none-eabihf --example qemu_panic_never
//! cargo run   --release --target thumbv7em-none-eabihf --example qemu_panic_never
//! ```
//!
//! Run under QEMU (mps2-an386), it plans the paper's line track by track
//! (`Mode::TrackWise` chosen at run time, about 5 s in QEMU), checks every
//! committed depth against the host's (`tests/qemu_support/expected.rs`,
//! bit for bit), prints the image's section sizes and the stack the line's
//! planning used, and exits 0. A link error naming
//! `error(panic-never): your program contains at least one panicking
//! branch` means a panic site: `tools/qemu/panic_sites.sh` lists them
//! (file:line in `src/`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(not(target_os = "none"))]
fn main() {}

#[cfg(target_os = "none")]
#[rustfmt::skip] // generated
#[path = "../tests/qemu_support/monterey.rs"]
mod monterey;

#[cfg(target_os = "none")]
#[allow(dead_code)]
#[path = "../tests/qemu_support/paper.rs"]
mod paper;

#[cfg(target_os = "none")]
#[allow(dead_code)]
#[rustfmt::skip] // generated
#[path = "../tests/qemu_support/expected.rs"]
mod expected;

#[cfg(target_os = "none")]
mod firmware {
    use core::hint::black_box;

    use auvnav_qemu::{exit, image, print, print_u32, stack};
    use cortex_m_rt::entry;
    #[cfg(not(auvnav_panic_probe))]
    use panic_never as _;

    use crate::{expected, paper};

    /// `tools/qemu/panic_sites.sh` builds with an ordinary panic handler to
    /// locate the panicking branches that break the link.
    #[cfg(auvnav_panic_probe)]
    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        exit(false)
    }

    fn line(label: &str, value: usize, unit: &str) {
        print(label);
        print_u32(u32::try_from(value).unwrap_or(u32::MAX));
        print(unit);
    }

    #[entry]
    fn main() -> ! {
        // Every setting opaque to the optimizer: all of `plan` stays linked.
        let cfg = black_box(paper::trackwise_config());
        let base = stack::repaint();
        let plans = paper::plan_line::<5>(cfg, |_, _, _| {});
        let used = stack::used_below(base);
        let Ok(plans) = plans else {
            print("qemu_panic_never: planning failed\n");
            exit(false)
        };
        let mut same = true;
        for (got, want) in plans.iter().zip(expected::TRACKWISE_K1.iter()) {
            same &= got.depth.to_bits() == want.depth.to_bits();
        }
        let s = image::sizes();
        print("qemu_panic_never: planned us_monterey_canyon_1 track-wise, ");
        print(if same {
            "depths equal to the host's\n"
        } else {
            "depths DIFFER from the host's\n"
        });
        line("  flash .text   ", s.text, " B\n");
        line("  flash .rodata ", s.rodata, " B\n");
        line("  flash .vector_table ", s.vectors, " B\n");
        line(
            "  RAM .data+.bss+.uninit ",
            s.data.saturating_add(s.bss).saturating_add(s.uninit),
            " B\n",
        );
        line("  stack used by the line's planning ", used, " B\n");
        exit(same)
    }
}
