//! The long soak of issue 21's mutation fuzz (`tests/fuzz.rs` is its bounded
//! CI run): the same seeded mutations of every input format, for as long as
//! asked, with a fresh seed per round; prints the counts per format and every
//! broken promise (the mutant is saved under `target/soak-failures/`).
//!
//! ```sh
//! cargo build --release && cargo run --release -p tetrefine-cli --example soak -- 3600 [SEED]
//! ```
//!
//! The CLI cases use `target/release/tetrefine` (or `$TETREFINE_BIN`).

#[path = "../tests/fuzz_common/mod.rs"]
mod fuzz_common;

use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seconds: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(600);
    let mut seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let keep = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/soak-failures");
    let t0 = Instant::now();
    let mut total: Vec<(&'static str, fuzz_common::Counts)> = Vec::new();
    let round = Duration::from_secs(120);
    let mut rounds = 0;
    while t0.elapsed() < Duration::from_secs(seconds) {
        let left = Duration::from_secs(seconds).saturating_sub(t0.elapsed());
        let counts = fuzz_common::fuzz(seed, usize::MAX, 25, round.min(left), &keep);
        for (name, c) in counts {
            match total.iter_mut().find(|(n, _)| *n == name) {
                Some((_, t)) => {
                    t.cases += c.cases;
                    t.ok += c.ok;
                    t.refused += c.refused;
                    t.cli_cases += c.cli_cases;
                    t.cli_ok += c.cli_ok;
                    t.cli_refused += c.cli_refused;
                    t.slowest = t.slowest.max(c.slowest);
                    t.failures.extend(c.failures);
                }
                None => total.push((name, c)),
            }
        }
        rounds += 1;
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        eprintln!(
            "round {rounds} done after {:.0} s: {} cases",
            t0.elapsed().as_secs_f64(),
            total
                .iter()
                .map(|(_, c)| c.cases + c.cli_cases)
                .sum::<usize>()
        );
    }
    println!(
        "soak: {rounds} rounds, {:.0} s\n{}",
        t0.elapsed().as_secs_f64(),
        fuzz_common::table(&total)
    );
    for (name, c) in &total {
        for (how, msg, file) in &c.failures {
            println!("FAIL {name}: {how}: {msg} [{}]", file.display());
        }
    }
}
