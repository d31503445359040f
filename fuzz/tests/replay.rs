//! Replays the saved inputs through the fuzz harnesses, without libFuzzer
//! (`cargo test` here; `scripts/fuzz.sh` replays the same files through
//! the fuzz targets first): every seed (`seeds/<target>/`) and every input
//! that once failed (`regressions/<target>/`, the crash files libFuzzer
//! wrote). A failing input panics here exactly as it did under the fuzzer.
//!
//! `cargo test --release -- --ignored --nocapture outcomes` prints what
//! random inputs do (how many are rejected, plan, fall back...), to check
//! that the input formats reach the interesting paths.

use std::collections::BTreeMap;
use std::path::Path;

type Harness = fn(&[u8]) -> String;

const TARGETS: [(&str, Harness); 3] = [
    ("planner", |d| format!("{:?}", auvnav_fuzz::planner::run(d))),
    ("simulate", |d| {
        format!("{:?}", auvnav_fuzz::simulate::run(d))
    }),
    ("tool_input", |d| format!("{:?}", auvnav_fuzz::tool::run(d))),
];

fn replay(dir: &str) -> usize {
    let mut n = 0;
    for (target, run) in TARGETS {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir).join(target);
        let Ok(entries) = std::fs::read_dir(&path) else {
            continue;
        };
        let mut files: Vec<_> = entries.filter_map(|e| Some(e.ok()?.path())).collect();
        files.sort();
        for f in files {
            let data = std::fs::read(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            eprintln!("{target}: {} -> {}", f.display(), run(&data));
            n += 1;
        }
    }
    n
}

#[test]
fn regressions() {
    replay("regressions");
}

#[test]
fn seeds() {
    assert!(replay("seeds") > 0, "no seeds found");
}

/// A small xorshift: reproducible random bytes without a dependency.
fn bytes(state: &mut u64, len: usize) -> Vec<u8> {
    (0..len)
        .map(|_| {
            *state ^= *state << 13;
            *state ^= *state >> 7;
            *state ^= *state << 17;
            (*state >> 24) as u8
        })
        .collect()
}

/// Random inputs, or with `FUZZ_CORPUS=1` the inputs of `corpus/<target>`;
/// `FUZZ_SHOW=text` saves the inputs whose outcome contains `text`.
#[test]
#[ignore = "statistics, not a check"]
fn outcomes() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let from_corpus = std::env::var_os("FUZZ_CORPUS").is_some();
    for (target, run) in TARGETS {
        let mut tally = BTreeMap::<String, usize>::new();
        let t0 = std::time::Instant::now();
        let inputs: Vec<Vec<u8>> = if from_corpus {
            let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("corpus")
                .join(target);
            std::fs::read_dir(dir)
                .map(|d| {
                    d.filter_map(|e| std::fs::read(e.ok()?.path()).ok())
                        .collect()
                })
                .unwrap_or_default()
        } else {
            (0..3000).map(|i| bytes(&mut state, 16 + i % 256)).collect()
        };
        let n = inputs.len();
        for (i, data) in inputs.into_iter().enumerate() {
            let outcome = std::panic::catch_unwind(|| run(&data)).unwrap_or_else(|_| {
                let path = std::env::temp_dir().join(format!("fuzz-outcomes-{target}-{i}"));
                let _ = std::fs::write(&path, &data);
                format!("PANIC (input saved to {})", path.display())
            });
            if std::env::var("FUZZ_SHOW").is_ok_and(|w| outcome.contains(&w)) {
                let path = std::env::temp_dir().join(format!("fuzz-show-{target}-{i}"));
                let _ = std::fs::write(&path, &data);
                println!("{outcome}: {}", path.display());
            }
            *tally.entry(outcome).or_default() += 1;
        }
        let dt = t0.elapsed().as_secs_f64();
        println!("{target}: {n} inputs in {dt:.2} s ({:.0}/s)", n as f64 / dt);
        for (k, v) in tally {
            println!("  {v:6}  {k}");
        }
    }
}

/// `FUZZ_INPUT=path cargo test --release -- --ignored --nocapture show`:
/// the decoded input (planner or simulate, by the file name), then its run.
#[test]
#[ignore = "a debugging aid"]
fn show() {
    use arbitrary::{Arbitrary, Unstructured};
    let Ok(path) = std::env::var("FUZZ_INPUT") else {
        return;
    };
    let data = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    if path.contains("simulate") {
        let i = auvnav_fuzz::simulate::Input::arbitrary_take_rest(Unstructured::new(&data));
        println!("{i:#?}");
        println!("{:?}", auvnav_fuzz::simulate::run(&data));
    } else if path.contains("planner") {
        let i = auvnav_fuzz::planner::Input::arbitrary_take_rest(Unstructured::new(&data));
        println!("{i:#?}");
        if let Ok(i) = &i {
            let step = match &i.vehicle {
                auvnav_fuzz::line::VehicleIn::CAuv4 => {
                    let v = auvnav_fuzz::line::c_auv4();
                    Some(v.speed() * v.sample_time())
                }
                auvnav_fuzz::line::VehicleIn::Tuned(t) => {
                    t.vehicle().map(|v| v.speed() * v.sample_time())
                }
            };
            if let Some(step) = step {
                println!("profile, waypoints: {:?}", i.line.parts(step));
            }
        }
        println!("{:?}", auvnav_fuzz::planner::run(&data));
    } else {
        println!("{:?}", String::from_utf8_lossy(&data));
        println!("{:?}", auvnav_fuzz::tool::run(&data));
    }
}
