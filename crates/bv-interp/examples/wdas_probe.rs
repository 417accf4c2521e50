#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]
use bv_interp::{Limits, Program, Value};
fn main() {
    let mut ok = 0;
    let mut n = 0;
    let mut paths: Vec<_> = std::fs::read_dir("/tmp/wdas-brdfs")
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    paths.sort();
    for path in paths {
        if path.extension().and_then(|e| e.to_str()) != Some("brdf") {
            continue;
        }
        if let Ok(only) = std::env::var("ONLY") {
            if !path.to_string_lossy().contains(&only) {
                continue;
            }
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let Some(s) = text.find("::begin shader") else {
            continue;
        };
        let e = text.find("::end shader").unwrap();
        let shader = &text[s + 14..e];
        let mut decls = String::new();
        let mut sets: Vec<(String, Value)> = Vec::new();
        if let (Some(ps), Some(pe)) = (
            text.find("::begin parameters"),
            text.find("::end parameters"),
        ) {
            for line in text[ps + 18..pe].lines() {
                let w: Vec<&str> = line.split_whitespace().collect();
                if w.len() < 2 || w[0].starts_with('#') {
                    continue;
                }
                let ty = match w[0] {
                    "float" => "float",
                    "color" => "vec3",
                    "bool" => "bool",
                    other => {
                        eprintln!("param type {other}");
                        continue;
                    }
                };
                decls.push_str(&format!("{ty} {};\n", w[1]));
                let num = |k: usize| w[w.len() - k].parse::<f64>().unwrap();
                let v = match ty {
                    "float" => Value::f(num(1)),
                    "vec3" => Value::vec3(num(3), num(2), num(1)),
                    _ => Value::Bool(num(1) != 0.0),
                };
                sets.push((w[1].to_string(), v));
            }
        }
        n += 1;
        let src = format!("#version 450\n{decls}{shader}\nvoid main() {{}}\n");
        let mut fe = naga::front::glsl::Frontend::default();
        let m = match fe.parse(
            &naga::front::glsl::Options::from(naga::ShaderStage::Fragment),
            &src,
        ) {
            Ok(m) => m,
            Err(e) => {
                println!(
                    "{:?}: PARSE {}",
                    path.file_name().unwrap(),
                    e.emit_to_string(&src)
                        .lines()
                        .take(4)
                        .collect::<Vec<_>>()
                        .join(" | ")
                );
                continue;
            }
        };
        let mut p = match Program::new(m) {
            Ok(p) => p,
            Err(e) => {
                println!("{:?}: NEW {e}", path.file_name().unwrap());
                continue;
            }
        };
        for (k, v) in sets {
            p.set_global(&k, v).unwrap();
        }
        let l = Value::vec3(0.3, 0.1, 0.948_683_298_050_513_8);
        let v = Value::vec3(-0.2, 0.4, 0.894_427_191);
        let r = p.call(
            "BRDF",
            &[
                l,
                v,
                Value::vec3(0.0, 0.0, 1.0),
                Value::vec3(1.0, 0.0, 0.0),
                Value::vec3(0.0, 1.0, 0.0),
            ],
            &Limits::default(),
        );
        let args = [
            Value::vec3(0.3, 0.1, 0.948_683_298_050_513_8),
            Value::vec3(-0.2, 0.4, 0.894_427_191),
            Value::vec3(0.0, 0.0, 1.0),
            Value::vec3(1.0, 0.0, 0.0),
            Value::vec3(0.0, 1.0, 0.0),
        ];
        let t = std::time::Instant::now();
        let k: usize = std::env::var("K")
            .ok()
            .and_then(|k| k.parse().ok())
            .unwrap_or(200_000);
        for _ in 0..k {
            std::hint::black_box(p.call("BRDF", &args, &Limits::default()).ok());
        }
        let rate = k as f64 / t.elapsed().as_secs_f64();
        println!(
            "{:?}: {:?} {:.0} evals/s",
            path.file_name().unwrap(),
            r.as_ref().map(|v| v.as_vec3()),
            rate
        );
        if r.is_ok() {
            ok += 1;
        }
    }
    println!("{ok}/{n} evaluated");
}
