//! Lobe meshes for Blender and friends: the surface `r(wo) · wo` the 3D view
//! draws (`bv_core::lobe::build`), as Wavefront
//! OBJ (one object per drawn BRDF, vertex colours as the `v x y z r g b`
//! extension Blender reads) or ASCII PLY (the primary BRDF, with per-vertex
//! colour and the raw value). Coordinates are the local shading frame
//! (+z the normal, which is Blender's up axis), in units of the shown
//! quantity (1/sr, or ln(1 + f) on the log scale).

use crate::session::build_scene;
use crate::session::state::AppState;
use crate::views::colormap;
use bv_core::lobe::{self, LobeMesh, LobeOptions, RadiusScale};
use std::fmt::Write as _;

/// Mesh resolution of exports (θ rings, φ segments): the view's idle one.
pub const RESOLUTION: (usize, usize) = crate::views::lobe3d::IDLE_RESOLUTION;

/// One BRDF's mesh with what is needed to colour it.
#[derive(Debug, Clone)]
pub struct Exported {
    /// Display name.
    pub label: String,
    /// Its display colour (sRGB).
    pub color: [u8; 3],
    /// Coloured by value (the primary BRDF) or in its own colour.
    pub by_value: bool,
    /// The mesh.
    pub mesh: LobeMesh,
}

/// The meshes of every drawn BRDF of `state` (primary first).
pub fn lobe_meshes(state: &AppState) -> Vec<Exported> {
    let mut runtime = crate::session::runtime::shared();
    runtime.sync(state);
    let scene = build_scene(state, &runtime, false);
    let d = state.display;
    let opts = LobeOptions {
        n_theta: RESOLUTION.0,
        n_phi: RESOLUTION.1,
        cosine: d.cosine,
        scale: if d.log {
            RadiusScale::Log
        } else {
            RadiusScale::Linear
        },
    };
    let primary = scene.primary().map(|b| b.id);
    let mut out: Vec<Exported> = scene
        .brdfs
        .iter()
        .map(|b| {
            let mesh = lobe::build(b.brdf.as_ref(), scene.wi(), &opts);
            Exported {
                label: b.label.clone(),
                color: b.rgb,
                by_value: Some(b.id) == primary && d.color_by_value,
                mesh,
            }
        })
        .collect();
    if let Some(p) = primary
        && let Some(i) = scene.brdfs.iter().position(|b| b.id == p)
    {
        out.swap(0, i);
    }
    out
}

/// The sRGB colour of vertex `k` (by value through the view's colour map, on
/// the same scale as the view: linear or ln(1 + v)).
fn vertex_color(e: &Exported, k: usize, log: bool) -> [u8; 3] {
    if !e.by_value {
        return e.color;
    }
    let v = e
        .mesh
        .values
        .get(k)
        .map_or(0.0, |v| (v[0] + v[1] + v[2]) / 3.0);
    let max = e.mesh.max_value as f32;
    let t = if max <= 0.0 {
        0.0
    } else if log {
        v.ln_1p() / max.ln_1p()
    } else {
        v / max
    };
    let c = colormap::viridis(t);
    [c.r(), c.g(), c.b()]
}

/// A header comment describing the scene.
fn describe(state: &AppState) -> Vec<String> {
    let d = state.display;
    vec![
        "bv lobe mesh: r(wo) * wo in the local shading frame (+z normal, +x tangent)".into(),
        format!(
            "radius r = {}{}; light at theta_i = {} deg, phi_i = {} deg",
            if d.cosine { "f * cos(theta_o)" } else { "f" },
            if d.log {
                " as ln(1 + value)"
            } else {
                " (1/sr)"
            },
            state.incident.theta_deg,
            state.incident.phi_deg
        ),
    ]
}

/// Wavefront OBJ with one object per mesh.
pub fn to_obj(state: &AppState, meshes: &[Exported]) -> String {
    let mut out = String::new();
    for line in describe(state) {
        let _ = writeln!(out, "# {line}");
    }
    let mut base = 1usize;
    for e in meshes {
        let m = &e.mesh;
        let name: String = e
            .label
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        let _ = writeln!(out, "o {name}");
        for (k, p) in m.positions.iter().enumerate() {
            let [r, g, b] = vertex_color(e, k, state.display.log);
            let _ = writeln!(
                out,
                "v {} {} {} {:.4} {:.4} {:.4}",
                p[0],
                p[1],
                p[2],
                f32::from(r) / 255.0,
                f32::from(g) / 255.0,
                f32::from(b) / 255.0
            );
        }
        for n in &m.normals {
            let _ = writeln!(out, "vn {} {} {}", n[0], n[1], n[2]);
        }
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [
                t[0] as usize + base,
                t[1] as usize + base,
                t[2] as usize + base,
            ];
            let _ = writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}");
        }
        base += m.positions.len();
    }
    out
}

/// ASCII PLY of one mesh, with normals, colours and the value per vertex.
pub fn to_ply(state: &AppState, e: &Exported) -> String {
    let m = &e.mesh;
    let mut out = String::new();
    out.push_str("ply\nformat ascii 1.0\n");
    for line in describe(state) {
        let _ = writeln!(out, "comment {line}");
    }
    let _ = writeln!(out, "comment BRDF: {}", e.label);
    let _ = writeln!(out, "element vertex {}", m.positions.len());
    out.push_str(
        "property float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n\
         property float value\n",
    );
    let _ = writeln!(out, "element face {}", m.indices.len() / 3);
    out.push_str("property list uchar uint vertex_indices\nend_header\n");
    for (k, p) in m.positions.iter().enumerate() {
        let n = m.normals.get(k).copied().unwrap_or([0.0, 0.0, 1.0]);
        let v = m.values.get(k).map_or(0.0, |v| (v[0] + v[1] + v[2]) / 3.0);
        let [r, g, b] = vertex_color(e, k, state.display.log);
        let _ = writeln!(
            out,
            "{} {} {} {} {} {} {r} {g} {b} {v}",
            p[0], p[1], p[2], n[0], n[1], n[2]
        );
    }
    for t in m.indices.chunks_exact(3) {
        let _ = writeln!(out, "3 {} {} {}", t[0], t[1], t[2]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> AppState {
        let mut s = AppState::default();
        s.add(bv_core::ModelSpec::new("lambert").unwrap());
        s.add(bv_core::ModelSpec::new("lambert").unwrap());
        s.selected = Some(s.brdfs[1].id);
        s
    }

    #[test]
    fn obj_indices_stay_in_range() {
        let s = state();
        let meshes = lobe_meshes(&s);
        assert_eq!(meshes.len(), 2);
        assert!(meshes[0].by_value && !meshes[1].by_value, "primary first");
        let obj = to_obj(&s, &meshes);
        let nv = obj.lines().filter(|l| l.starts_with("v ")).count();
        assert_eq!(
            nv,
            meshes.iter().map(|m| m.mesh.positions.len()).sum::<usize>()
        );
        for l in obj.lines().filter(|l| l.starts_with("f ")) {
            for idx in l[2..].split(' ') {
                let i: usize = idx.split("//").next().unwrap().parse().unwrap();
                assert!(i >= 1 && i <= nv, "{l}");
            }
        }
        assert_eq!(obj.matches("\no ").count(), 2);
    }

    #[test]
    fn ply_header_matches_the_body() {
        let s = state();
        let meshes = lobe_meshes(&s);
        let ply = to_ply(&s, &meshes[0]);
        let (head, body) = ply.split_once("end_header\n").unwrap();
        let nv: usize = head
            .lines()
            .find_map(|l| l.strip_prefix("element vertex "))
            .unwrap()
            .parse()
            .unwrap();
        let nf: usize = head
            .lines()
            .find_map(|l| l.strip_prefix("element face "))
            .unwrap()
            .parse()
            .unwrap();
        assert_eq!(body.lines().count(), nv + nf);
        // Lambert: every upper-hemisphere vertex sits at radius albedo/π.
        let first: Vec<f32> = body
            .lines()
            .next()
            .unwrap()
            .split(' ')
            .take(3)
            .map(|x| x.parse().unwrap())
            .collect();
        let r = (first[0].powi(2) + first[1].powi(2) + first[2].powi(2)).sqrt();
        assert!((r - 0.5 / std::f32::consts::PI).abs() < 1e-5, "{r}");
    }
}
