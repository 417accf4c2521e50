//! Every test file of `tests/data/brdf/` through the front end and the GPU
//! port: the good ones compile, the broken and hostile ones are refused with
//! their place in the file.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/brdf")
        .join(name)
}

fn compile(name: &str) -> bv_user::Result<bv_user::Compiled> {
    let text = std::fs::read_to_string(data(name)).unwrap();
    bv_user::compile(&text, name)
}

#[test]
fn print_all() {
    for e in std::fs::read_dir(data("")).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        match compile(&name) {
            Ok(c) => println!(
                "{name}: OK {} params, {} bytes",
                c.decls.len(),
                c.wgsl.len()
            ),
            Err(e) => println!("{name}: ERR {e}"),
        }
    }
}
