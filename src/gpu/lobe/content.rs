//! The part of a lobe frame's target that its meshes and lines can cover:
//! where the copy into egui's pass needs FXAA.
//!
//! FXAA changes a pixel only where its 3 × 3 neighbourhood holds an edge; a
//! pixel whose neighbours all show the background is copied as it stands.
//! On a CPU rasteriser the FXAA copy cost 27–30 ms of a 1600 × 1200 figure
//! (2-core Xeon, lavapipe): it runs under execution masks, so its early
//! return for non-edge pixels skips next to nothing, and every pixel paid
//! for nine texel loads. A lobe seldom covers more than half of its view,
//! so the copy is split: the plain copy everywhere, FXAA again over the
//! rectangle found here. The pixels are the same as FXAA everywhere
//! (`tests/gui.rs`: `smoothing_only_the_content_changes_no_pixel`).

use super::LobeFrame;
use glam::Vec4;

/// Pixels added on every side of the covered rectangle: one for FXAA's
/// neighbourhood, and one for rounding between this projection (f32 on the
/// CPU) and the rasteriser's.
const MARGIN: f32 = 2.0;

/// Where a frame's copy needs FXAA, in pixels of its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Content {
    /// Nothing is drawn: the plain copy is the whole image.
    Empty,
    /// `[x, y, width, height]`: everything drawn lies inside, with a margin.
    Within([u32; 4]),
    /// Anywhere: what is drawn spans the target, or a point lies at or
    /// behind the camera's plane, where the projection bounds nothing.
    Everywhere,
}

/// The rectangle of a `size`-pixel target that `frame`'s meshes and lines
/// can cover, with [`MARGIN`] pixels about it; `ppp` scales line widths, as
/// the renderer does.
///
/// Meshes: every vertex position, scaled by its style's scale as the vertex
/// shader does (`shaders/lobe.wgsl`), projected. Lines: both ends, widened
/// by half the line's width and the half pixel of its anti-aliased edge
/// (`shaders/lines.wgsl`). A triangle's pixels lie in the bounding box of
/// its corners, and a line's quad in that of its ends widened.
pub fn content(frame: &LobeFrame, size: [u32; 2], ppp: f32) -> Content {
    let m = frame.camera.view_proj;
    let [w, h] = [size[0] as f32, size[1] as f32];
    let mut lo = [f32::INFINITY; 2];
    let mut hi = [f32::NEG_INFINITY; 2];
    // Adds a point in clip space with `pad` pixels about it; false where it
    // lies at or behind the camera's plane.
    let mut add = |c: Vec4, pad: f32| -> bool {
        if !c.is_finite() {
            // Not drawn (a NaN vertex) or not boundable: skip a NaN, give
            // up on an infinity.
            return c.is_nan();
        }
        if c.w <= 1e-6 {
            return false;
        }
        let x = (c.x / c.w + 1.0) * 0.5 * w;
        let y = (1.0 - c.y / c.w) * 0.5 * h;
        lo = [lo[0].min(x - pad), lo[1].min(y - pad)];
        hi = [hi[0].max(x + pad), hi[1].max(y + pad)];
        true
    };
    for d in &frame.meshes {
        let s = d.style.scale;
        for p in &d.mesh.positions {
            let c = m * Vec4::new(p[0] * s, p[1] * s, p[2] * s, 1.0);
            if !add(c, 0.0) {
                return Content::Everywhere;
            }
        }
    }
    for l in &frame.lines {
        let pad = 0.5 * l.width[0] * ppp + 0.5;
        for e in [l.a, l.b] {
            if !add(m * Vec4::new(e[0], e[1], e[2], 1.0), pad) {
                return Content::Everywhere;
            }
        }
    }
    if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
        return Content::Empty;
    }
    let x0 = (lo[0] - MARGIN).floor().clamp(0.0, w);
    let y0 = (lo[1] - MARGIN).floor().clamp(0.0, h);
    let x1 = (hi[0] + MARGIN).ceil().clamp(0.0, w);
    let y1 = (hi[1] + MARGIN).ceil().clamp(0.0, h);
    if x1 <= x0 || y1 <= y0 {
        // All of it off the target.
        return Content::Empty;
    }
    if x0 == 0.0 && y0 == 0.0 && x1 == w && y1 == h {
        // One FXAA copy, not the plain copy under it as well.
        return Content::Everywhere;
    }
    Content::Within([x0 as u32, y0 as u32, (x1 - x0) as u32, (y1 - y0) as u32])
}

/// `rect` of a `target`-pixel image drawn stretched over `viewport`
/// (`[x, y, width, height]` in the pass's pixels), as a scissor rectangle of
/// the pass, within `clip`; `None` where nothing of it remains.
pub(super) fn scissor(
    rect: [u32; 4],
    target: [u32; 2],
    viewport: [u32; 4],
    clip: [u32; 4],
) -> Option<[u32; 4]> {
    let map = |v: u32, t: u32, from: u32, len: u32, up: bool| -> u64 {
        // v · len / t, rounded outwards, in integers (no f32 rounding at
        // 16384-pixel sides).
        let (num, den) = (u64::from(v) * u64::from(len), u64::from(t.max(1)));
        u64::from(from) + if up { num.div_ceil(den) } else { num / den }
    };
    let [x, y, w, h] = rect;
    let x0 = map(x, target[0], viewport[0], viewport[2], false);
    let x1 = map(x + w, target[0], viewport[0], viewport[2], true);
    let y0 = map(y, target[1], viewport[1], viewport[3], false);
    let y1 = map(y + h, target[1], viewport[1], viewport[3], true);
    let [cx, cy, cw, ch] = clip.map(u64::from);
    let (x0, x1) = (x0.max(cx), x1.min(cx + cw));
    let (y0, y1) = (y0.max(cy), y1.min(cy + ch));
    (x1 > x0 && y1 > y0)
        .then(|| [x0, y0, x1 - x0, y1 - y0].map(|v| u32::try_from(v).unwrap_or(u32::MAX)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rectangle_maps_onto_the_viewport_within_the_clip() {
        // (rect, target, viewport, clip, scissor).
        type Case = ([u32; 4], [u32; 2], [u32; 4], [u32; 4], Option<[u32; 4]>);
        #[rustfmt::skip]
        let cases: [Case; 5] = [
            // Pixel for pixel, offset by the viewport.
            ([10, 20, 30, 40], [100, 100], [5, 7, 100, 100], [0, 0, 500, 500], Some([15, 27, 30, 40])),
            // Stretched: rounded outwards.
            ([1, 1, 1, 1], [3, 3], [0, 0, 6, 6], [0, 0, 6, 6], Some([2, 2, 2, 2])),
            ([1, 1, 1, 1], [3, 3], [0, 0, 4, 4], [0, 0, 4, 4], Some([1, 1, 2, 2])),
            // Cut by the clip, or wholly outside it.
            ([0, 0, 50, 50], [100, 100], [0, 0, 100, 100], [25, 30, 100, 100], Some([25, 30, 25, 20])),
            ([0, 0, 10, 10], [100, 100], [0, 0, 100, 100], [50, 50, 10, 10], None),
        ];
        for (rect, target, viewport, clip, want) in cases {
            assert_eq!(
                scissor(rect, target, viewport, clip),
                want,
                "{rect:?} of {target:?} over {viewport:?} within {clip:?}"
            );
        }
    }
}
