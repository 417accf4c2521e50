"""bv's Python module against Mitsuba 3 on 10⁶ BRDF evaluations (issue 30).

    python benches/python_eval.py [--pairs 1000000] [--repeat 5]

Times `bv.Model("cook-torrance", …).eval(wi, wo)` on N random pairs from
numpy (conversion in and out included: float64 (N, 3) arrays in, a float32
(N, 3) array out), with the f64 reference path for comparison, and, when
`import mitsuba` works, Mitsuba 3's `llvm_ad_rgb` `roughconductor` (GGX,
α = 0.3, η = 0.2, k = 3.9) `bsdf.eval` on the same pairs from numpy (wrapping the arrays as
Mitsuba vectors and the result back to numpy included). The bv model is the
matching GGX conductor: the same α, a conductor Fresnel term, Smith G.
Prints the best of `--repeat` runs of each, in M evals/s, and the CPU's
vector extensions.
"""

import argparse
import math
import re
import time

import numpy as np

import bv


# A conductor with one η and k for all channels (Mitsuba's RGB variants take
# a float; an RGB value above 1 is refused as a reflectance).
ETA = 0.2
K = 3.9


def pairs(n, seed=30):
    """Uniform directions on the upper hemisphere, as (N, 3) float64."""
    rng = np.random.default_rng(seed)

    def dirs():
        z = rng.uniform(0.0, 1.0, n)
        phi = rng.uniform(0.0, 2 * math.pi, n)
        s = np.sqrt(1 - z * z)
        return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)

    return dirs(), dirs()


def best(f, repeat):
    """The shortest of `repeat` timed calls of f (after one warm-up)."""
    f()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def cpu():
    try:
        text = open("/proc/cpuinfo").read()
    except OSError:
        return "unknown CPU"
    name = re.search(r"model name\s*:\s*(.*)", text)
    avx = sorted(set(re.findall(r"\b(avx[^ \n]*)", text)))
    cores = len(re.findall(r"^processor", text, re.M))
    return f"{name.group(1) if name else 'CPU'}, {cores} logical cores, {' '.join(avx) or 'no AVX'}"


def mitsuba_case(wi, wo, repeat):
    """Mitsuba 3's roughconductor eval on the same pairs, or None."""
    try:
        import mitsuba as mi
    except ImportError:
        return None
    mi.set_variant("llvm_ad_rgb")
    bsdf = mi.load_dict(
        {
            "type": "roughconductor",
            "distribution": "ggx",
            "alpha": 0.3,
            "eta": ETA,
            "k": K,
        }
    )
    ctx = mi.BSDFContext()

    def run():
        # Directions in the local shading frame (normal +z), as bv's.
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(wi[:, 0], wi[:, 1], wi[:, 2])
        v = bsdf.eval(ctx, si, mi.Vector3f(wo[:, 0], wo[:, 1], wo[:, 2]))
        # Back to an (N, 3) numpy array: part of the cost, as bv's output is.
        a = np.array(v)
        return a.T if a.shape[0] == 3 and a.ndim == 2 else a

    t = best(run, repeat)
    return t, mi.__version__, run()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    wi, wo = pairs(a.pairs)
    m = bv.Model(
        "cook-torrance",
        alpha=0.3,
        kd=0,
        ks=1,
        distribution="ggx",
        geometry="smith",
        fresnel="conductor",
        eta=[ETA] * 3,
        k=[K] * 3,
    )
    kernel, isa = m.dispatch()
    print(f"CPU: {cpu()}")
    print(f"bv {m.id}: kernel {kernel} ({isa}), {a.pairs} pairs, best of {a.repeat}")
    t = best(lambda: m.eval(wi, wo), a.repeat)
    print(f"  bv eval (f32 kernels):   {a.pairs / t / 1e6:8.2f} M evals/s ({t * 1e3:.1f} ms)")
    t64 = best(lambda: m.eval(wi, wo, precision="f64"), a.repeat)
    print(f"  bv eval (f64 reference): {a.pairs / t64 / 1e6:8.2f} M evals/s ({t64 * 1e3:.1f} ms)")
    r = mitsuba_case(wi, wo, a.repeat)
    if r is None:
        print("  mitsuba: not installed (pip install mitsuba in a dev venv to compare)")
    else:
        tm, ver, mv = r
        print(f"  mitsuba {ver} llvm_ad_rgb roughconductor: {a.pairs / tm / 1e6:8.2f} M evals/s ({tm * 1e3:.1f} ms)")
        print(f"  bv speed / mitsuba speed: {tm / t:.2f}x")
        # The same case? Mitsuba's eval includes cos θo; compare where both
        # are well above f32 noise.
        f = m.eval(wi, wo, precision="f64") * wo[:, 2:3]
        ok = (wi[:, 2] > 0.05) & (wo[:, 2] > 0.05) & (f.max(axis=1) > 1e-3)
        rel = np.abs(mv[ok] - f[ok]) / f[ok]
        print(f"  bv f·cos vs mitsuba: median rel. difference {np.median(rel):.2e}, 99th percentile {np.quantile(rel, 0.99):.2e}")


if __name__ == "__main__":
    main()
