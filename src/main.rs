//! `bv`: an interactive BRDF viewer. With no sub-command it opens the viewer;
//! sub-commands (`eval`, `check`, `models`, `bench`, …) print results for scripts.

fn main() -> std::process::ExitCode {
    bv::cli::main(&bv::app::SHELL)
}
