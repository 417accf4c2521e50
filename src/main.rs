//! `bv`: an interactive BRDF viewer. With no sub-command it opens the viewer;
//! sub-commands (`eval`, `check`, `models`, `bench`, …) print results for scripts.
//! Built for `wasm32-unknown-unknown`, the same binary is the page's viewer.

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    bv::cli::main(&bv::app::SHELL)
}

#[cfg(target_arch = "wasm32")]
fn main() {
    bv::app::web::start();
}
