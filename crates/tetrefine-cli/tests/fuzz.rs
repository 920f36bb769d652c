//! Issue 21's mutation fuzz, bounded for CI: thousands of seeded mutations
//! of every shipped input format (Medit, Gmsh 2.2/4.1 ASCII and binary, VTU
//! in five layouts, GiD, each file of a TetGen set), of indicator and size
//! files, of surfaces (.obj, .off, .ply) and of mesher inputs (.poly, .off,
//! ASCII and binary .stl), read in-process, and a sample of them through the
//! command line. `examples/soak.rs` runs the same cases for as long as asked.
//!
//! Asserted for every case (see `fuzz_common`): no panic, an error names the
//! file, a success passes `check()`; through the CLI, no output and no
//! temporary file after an error, and a readable, checked output after a
//! success. Mutants that break a promise are saved under
//! `target/fuzz-failures/` and become fixtures in `tests/bad/`.

mod fuzz_common;

use std::time::Duration;

/// In-process cases per seed (if time allows).
const PER_SEED: usize = 3000;
/// Every this many cases also through the CLI.
const CLI_EVERY: usize = 100;
/// The whole run's time budget, shared evenly between the seeds.
const BUDGET: Duration = Duration::from_secs(55);

#[test]
fn mutated_inputs_of_every_format_never_break_a_promise() {
    let keep = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/fuzz-failures");
    let counts = fuzz_common::fuzz(0x5EED_2026_1202, PER_SEED, CLI_EVERY, BUDGET, &keep);
    let table = fuzz_common::table(&counts);
    println!("{table}");
    let mut failures = Vec::new();
    for (name, c) in &counts {
        for (how, msg, file) in &c.failures {
            failures.push(format!("{name}: {how}: {msg} [{}]", file.display()));
        }
    }
    assert!(failures.is_empty(), "{}\n{table}", failures.join("\n"));
    // Enough cases to mean something (thousands per format family even on
    // a loaded 2-core machine), and refusals seen for every seed.
    for (name, c) in &counts {
        assert!(c.cases >= 300, "{name}: only {} cases\n{table}", c.cases);
        assert!(c.refused > 0, "{name}: no mutant was refused\n{table}");
    }
    let total: usize = counts.iter().map(|(_, c)| c.cases).sum();
    assert!(total >= 15_000, "{total} cases\n{table}");
}
