#!/usr/bin/env python3
"""gsplat's side of `sadsplat_bench_rasterizer --device cuda` (not part of sadsplat): the same
random in-frustum Gaussians (drawn with the same torch calls, seed and order, so with the same
LibTorch they are the same numbers), the same camera, the same timing (forward without grad,
then forward + backward of rgb.sum() + features.sum(), mean of REPEATS after WARMUP).
With features, SH colours come from gsplat's spherical_harmonics and one rasterization call
renders RGB + features, as a semantic trainer on gsplat would do it.

  PYTHONPATH=<gsplat source> python3 bench_rasterizer_gsplat.py [--gaussians 100000,500000,1000000]
      [--features 0,32] [--width 800] [--height 450] [--repeats 20] [--warmup 3] [--packed]
"""
import argparse
import time

import torch


def random_in_frustum(n, c, width, height, fx, fy, cx, cy):
    torch.manual_seed(0)
    z = 2.0 + 8.0 * torch.rand(n, 1)
    u = torch.rand(n, 1) * width
    v = torch.rand(n, 1) * height
    g = {"means": torch.cat([(u - cx) / fx * z, (v - cy) / fy * z, z], 1),
         "quats": torch.randn(n, 4),
         "log_scales": torch.log(0.01 + 0.025 * torch.rand(n, 3)),
         "opacity_logits": torch.randn(n),
         "sh": torch.randn(n, 16, 3) * 0.2,
         "features": torch.randn(n, c)}
    return {k: t.cuda().requires_grad_(True) for k, t in g.items()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gaussians", default="100000,500000,1000000")
    ap.add_argument("--features", default="0,32")
    ap.add_argument("--width", type=int, default=800)
    ap.add_argument("--height", type=int, default=450)
    ap.add_argument("--repeats", type=int, default=20)
    ap.add_argument("--warmup", type=int, default=3)
    ap.add_argument("--packed", action="store_true")
    args = ap.parse_args()
    from gsplat import rasterization, spherical_harmonics

    w, h = args.width, args.height
    fx = fy = 0.8 * w
    cx, cy = w / 2.0, h / 2.0
    K = torch.tensor([[fx, 0, cx], [0, fy, cy], [0, 0, 1]], device="cuda")[None]
    view = torch.eye(4, device="cuda")[None]
    print(f"gsplat, image={w}x{h} repeats={args.repeats} packed={args.packed}")
    print("| gaussians | features | forward ms | forward+backward ms |")
    print("|---|---|---|---|")
    for n in [int(x) for x in args.gaussians.split(",")]:
        for c in [int(x) for x in args.features.split(",")]:
            g = random_in_frustum(n, c, w, h, fx, fy, cx, cy)

            def render():
                opac = torch.sigmoid(g["opacity_logits"])
                scales = torch.exp(g["log_scales"])
                if c == 0:
                    img, _, _ = rasterization(g["means"], g["quats"], scales, opac, g["sh"], view, K,
                                              w, h, sh_degree=3, packed=args.packed)
                    return img.sum()
                colours = torch.clamp_min(spherical_harmonics(3, g["means"], view, g["sh"]) + 0.5, 0.0)
                img, _, _ = rasterization(g["means"], g["quats"], scales, opac,
                                          torch.cat([colours, g["features"][None]], -1), view, K, w, h,
                                          sh_degree=None, packed=args.packed,
                                         channel_chunk=64)  # one launch (default 32 splits 35 into 32 + 3)
                return img.sum()

            fwd = both = 0.0
            for it in range(args.warmup + args.repeats):
                torch.cuda.synchronize()
                t0 = time.perf_counter()
                with torch.no_grad():
                    render()
                torch.cuda.synchronize()
                t1 = time.perf_counter()
                render().backward()
                torch.cuda.synchronize()
                t2 = time.perf_counter()
                if it >= args.warmup:
                    fwd += (t1 - t0) * 1000
                    both += (t2 - t1) * 1000
            print(f"| {n} | {c} | {fwd / args.repeats:.2f} | {both / args.repeats:.2f} |", flush=True)
            del g
            torch.cuda.empty_cache()


if __name__ == "__main__":
    main()
