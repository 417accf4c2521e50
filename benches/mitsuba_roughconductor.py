"""Mitsuba 3's rough conductor on the case `bv bench` measures, for the README's
speed comparison (run it interleaved with `bv bench ... --json`).

    pip install mitsuba   # plus Debian's libllvm19 for the LLVM variant
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \
        python3 benches/mitsuba_roughconductor.py [pairs]

GGX, alpha 0.3, eta (0.2, 0.92, 1.1), k (3.9, 2.45, 2.14), uniform-hemisphere
pairs from PCG32, fresh pairs for each timing. The timed region is
`bsdf.eval` + `dr.eval` + `dr.sync_thread` (Dr.Jit's LLVM backend launches
kernels asynchronously: without the sync it reads tens of G evals/s); best of 7.
"""
import sys
import time

import drjit as dr
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
bsdf = mi.load_dict({
    "type": "roughconductor",
    "distribution": "ggx",
    "alpha": 0.3,
    "eta": {"type": "rgb", "value": [0.2, 0.92, 1.1]},
    "k": {"type": "rgb", "value": [3.9, 2.45, 2.14]},
})
n = int(float(sys.argv[1])) if len(sys.argv) > 1 else 1_000_000
rng = mi.PCG32(n)


def directions():
    u = mi.Point2f(rng.next_float32(), rng.next_float32())
    return mi.warp.square_to_uniform_hemisphere(u)


si = dr.zeros(mi.SurfaceInteraction3f, n)
ctx = mi.BSDFContext()
best = float("inf")
for _ in range(7):
    si.wi = directions()
    wo = directions()
    dr.eval(si.wi, wo)
    dr.sync_thread()
    t = time.perf_counter()
    value = bsdf.eval(ctx, si, wo)
    dr.eval(value)
    dr.sync_thread()
    best = min(best, time.perf_counter() - t)
print(f"mitsuba {mi.__version__} llvm_ad_rgb roughconductor: {n / best / 1e6:.1f} M evals/s "
      f"(best of 7, {n} pairs, {dr.thread_count()} threads)")
