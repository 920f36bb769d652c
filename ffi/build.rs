//! Compiles the C++ shim against TetGen's header and links Debian's `libtet`.
//!
//! Debian's `libtet1.5-dev` installs `/usr/include/tetgen.h` and
//! `libtet.so` (no static library). `TETGEN_INCLUDE_DIR` and `TETGEN_LIB_DIR`
//! point elsewhere when TetGen lives outside the system paths.

use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=src/shim.cpp");
    println!("cargo:rerun-if-env-changed=TETGEN_INCLUDE_DIR");
    println!("cargo:rerun-if-env-changed=TETGEN_LIB_DIR");
    let include = std::env::var_os("TETGEN_INCLUDE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/include"));
    if !include.join("tetgen.h").is_file() {
        panic!(
            "tetgen.h not found in {}: install TetGen's library and header \
             (Debian/Ubuntu: `apt-get install libtet1.5-dev`) or set TETGEN_INCLUDE_DIR",
            include.display()
        );
    }
    cc::Build::new()
        .cpp(true)
        .file("src/shim.cpp")
        .include(&include)
        .define("TETLIBRARY", None)
        .flag_if_supported("-std=c++11")
        // tetgen.h itself is not warning-free; the shim is small and reviewed.
        .warnings(false)
        .compile("tetgen_shim");
    if let Some(dir) = std::env::var_os("TETGEN_LIB_DIR") {
        println!(
            "cargo:rustc-link-search=native={}",
            PathBuf::from(dir).display()
        );
    }
    println!("cargo:rustc-link-lib=dylib=tet");
}
