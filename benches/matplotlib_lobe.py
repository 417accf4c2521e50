#!/usr/bin/env python3
"""The matplotlib side of the README's `bv render` start-up comparison.

Draws the same figure `bv render --view lobe3d --width 1600 --height 1200` draws: the
reflectance lobe of one BRDF for a light at (theta_i, phi_i) = (45 deg, 0), sampled on a
128 x 256 (theta_o, phi_o) grid, as a shaded 3-D surface whose radius is f(wi, wo) and whose
colour is viridis(f / max f), saved as a 1600 x 1200 PNG. Time it from process start, the way
a user runs it:

    /usr/bin/time -f %e python3 benches/matplotlib_lobe.py --out /tmp/lobe.png
    /usr/bin/time -f %e target/release/bv render --view lobe3d --out /tmp/lobe.png

`--model cook-torrance` draws a GGX / Smith / Schlick lobe (alpha 0.3, F0 0.04) instead of
Lambert, so the script's own evaluation is not the trivial constant; the two take the same
time within noise, which says the cost is matplotlib's start-up and rasterisation.
"""

import argparse
import math

import matplotlib

matplotlib.use("Agg")  # headless: no display, as `bv render` has none
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def lambert(wi, wo):
    """Lambert with albedo 0.5: f = 0.5 / pi everywhere above the surface."""
    return np.full(wo.shape[:-1], 0.5 / math.pi)


def cook_torrance(wi, wo, alpha=0.3, f0=0.04):
    """Cook-Torrance with the GGX distribution (Walter et al. 2007, eq. 33), the
    height-correlated Smith masking term (Heitz 2014, eq. 99) and Schlick's Fresnel."""
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    cos_h = h[..., 2]
    a2 = alpha * alpha
    d = a2 / (math.pi * (cos_h * cos_h * (a2 - 1.0) + 1.0) ** 2)

    def lam(cos_t):
        tan2 = (1.0 - cos_t * cos_t) / np.maximum(cos_t * cos_t, 1e-12)
        return 0.5 * (np.sqrt(1.0 + a2 * tan2) - 1.0)

    cos_i = wi[2]
    cos_o = np.maximum(wo[..., 2], 1e-6)
    g = 1.0 / (1.0 + lam(cos_i) + lam(cos_o))
    f = f0 + (1.0 - f0) * (1.0 - np.sum(wi * h, axis=-1)) ** 5
    return d * g * f / (4.0 * cos_i * cos_o)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", choices=["lambert", "cook-torrance"], default="lambert")
    parser.add_argument("--out", default="/tmp/matplotlib_lobe.png")
    args = parser.parse_args()

    theta_i = math.radians(45.0)
    wi = np.array([math.sin(theta_i), 0.0, math.cos(theta_i)])
    theta = np.linspace(0.0, math.pi / 2, 128)
    phi = np.linspace(0.0, 2.0 * math.pi, 256)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    wo = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    brdf = lambert if args.model == "lambert" else cook_torrance
    f = brdf(wi, wo)
    x, y, z = (f[..., None] * wo).transpose(2, 0, 1)

    fig = plt.figure(figsize=(16, 12), dpi=100)
    fig.patch.set_facecolor("#1b1c1e")
    ax = fig.add_subplot(projection="3d")
    ax.set_facecolor("#1b1c1e")
    colours = plt.cm.viridis(f / f.max())
    ax.plot_surface(x, y, z, facecolors=colours, rstride=1, cstride=1, linewidth=0, shade=True)
    r = float(f.max())
    ax.quiver(0, 0, 0, *(1.2 * r * wi), color="#ffe066")
    ax.set_box_aspect((1, 1, 0.5))
    ax.set_axis_off()
    m = plt.cm.ScalarMappable(cmap="viridis")
    m.set_array(f)
    fig.colorbar(m, ax=ax, shrink=0.4, label="f (1/sr)")
    fig.savefig(args.out, dpi=100, facecolor=fig.get_facecolor())


if __name__ == "__main__":
    main()
