#!/usr/bin/env python3
"""Like-for-like reference for speed comparisons (not part of sadsplat): sadsplat's Net-1
training (RGB + 32 semantic feature channels, no drop, no pseudo-labels) written on gsplat, fed
from the same scene cache (docs/formats.md, read here without sadsplat).

Same as `sadsplat train CACHE --device cuda --drop none --no-pseudo-labels`, as far as gsplat
allows: the same initial Gaussians (one per sparse point, scale = mean distance to 3 nearest
neighbours, opacity 0.1, features N(0, 0.01)), iterations, learning rates (position decaying
exponentially from 1.6e-4 to 1.6e-6 x scene extent), SH degree +1 every 1000 iterations, loss
(0.8 L1 + 0.2 (1 - SSIM) on the masked training view; on every second iteration a labelled view
too, rendered with 32 more channels and decoded by a linear layer, loss 1 - cosine to the one-hot
class), Adam (fused, as gsplat's simple_trainer). Densification is gsplat's DefaultStrategy with
sadsplat's schedule and thresholds (from 500 to iterations/2 every 100, gradient 2e-4, dense 0.01
x extent, opacity reset every 3000). SSIM (11-tap Gaussian window, sigma 1.5, zero padding, as
sadsplat's) is by default the fused CUDA SSIM that gsplat's own trainer uses (`fused-ssim`,
https://github.com/rahul-goel/fused-ssim, built just in time from its source in FUSED_SSIM_SRC,
default .deps/fused-ssim; padding "same" = sadsplat's definition; its value is checked against the
torch composition below at start); --ssim torch uses that composition of torch convolutions,
--ssim-weight 0 none.

  PYTHONPATH=<gsplat source> python3 train_gsplat.py CACHE [--iterations 7000] [--json OUT.json]
"""
import argparse
import json
import math
import struct
import sys
import time

import torch
import torch.nn.functional as F


def fail(path, field, expected):
    sys.exit(f"train_gsplat.py: {path}: {field}: expected {expected}")


def med_decode(residuals):
    """Undoes the median edge prediction of scene cache version 3 (docs/formats.md) on a stack
    of planes [N, H, W] of one size: pixel = residual + predictor (mod 256), the predictor from
    the left (a), above (b) and above-left (c) pixels. A pixel needs only pixels of earlier
    anti-diagonals, so each anti-diagonal of every plane is decoded at once."""
    import numpy as np
    r = residuals.astype(np.int32)
    n, h, w = r.shape
    v = np.zeros_like(r)
    v[:, 0, :] = np.cumsum(r[:, 0, :], axis=1) % 256  # first row: the left pixel (0 first)
    for y in range(1, h):  # first column: the pixel above
        v[:, y, 0] = (v[:, y - 1, 0] + r[:, y, 0]) % 256
    for d in range(2, h + w - 1):  # the pixels x + y = d with x, y >= 1
        y = np.arange(max(1, d - w + 1), min(h - 1, d - 1) + 1)
        x = d - y
        a, b, c = v[:, y, x - 1], v[:, y - 1, x], v[:, y - 1, x - 1]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        pred = np.where(c >= hi, lo, np.where(c <= lo, hi, a + b - c))
        v[:, y, x] = (pred + r[:, y, x]) % 256
    return v.astype(np.uint8)


def read_cache(path):
    """The views, classes and points of a sadsplat scene cache, versions 1-3 (docs/formats.md),
    read without sadsplat."""
    import zlib
    import numpy as np
    data = open(path, "rb").read()
    if len(data) < 32 or data[:8] != b"SADSCENE":
        fail(path, "magic", "SADSCENE (a sadsplat scene cache)")
    version, _flags, size, _hash = struct.unpack_from("<IIQQ", data, 8)
    if version not in (1, 2, 3) or size != len(data) - 32:
        fail(path, "header", "version 1, 2 or 3 and payload size = file size - 32")
    classes, views, points = [], [], None
    pending = {}  # (h, w) -> [(view, key, channels, residual planes [c, h, w])]
    pos, end = 32, len(data)

    def string(p):
        (n,) = struct.unpack_from("<I", data, p)
        return data[p + 4:p + 4 + n].decode("utf-8", "replace"), p + 4 + n

    def plane(p, view, key, w, h, channels):
        if version < 3:
            count = w * h * channels
            raw = np.frombuffer(data, dtype=np.uint8, count=count, offset=p)
            view[key] = torch.from_numpy(raw.reshape(h, w, channels).copy())
            return p + count
        (n,) = struct.unpack_from("<Q", data, p)
        raw = zlib.decompress(data[p + 8:p + 8 + n], wbits=-15)
        if len(raw) != w * h * channels:
            fail(path, f"view {view['name']}: {key}", f"{w * h * channels} bytes, got {len(raw)}")
        planes = np.frombuffer(raw, dtype=np.uint8).reshape(channels, h, w)
        pending.setdefault((h, w), []).append((view, key, channels, planes))
        return p + 8 + n

    while pos + 12 <= end:
        tag = data[pos:pos + 4]
        (n,) = struct.unpack_from("<Q", data, pos + 4)
        c, nxt = pos + 12, pos + 12 + n
        if tag == b"CLAS":
            (count,) = struct.unpack_from("<I", data, c)
            p = c + 4
            for _ in range(count):
                name, p = string(p)
                p += 3
                _, p = string(p)
                classes.append(name)
        elif tag == b"VIEW":
            name, p = string(c)
            w, h = struct.unpack_from("<II", data, p)
            p += 8
            fx, fy, cx, cy = struct.unpack_from("<4d", data, p)
            p += 32
            q = struct.unpack_from("<4d", data, p)
            p += 32
            t = struct.unpack_from("<3d", data, p)
            p += 24
            roles, has_labels = data[p], data[p + 1]
            p += 2
            view = dict(name=name, w=w, h=h, K=(fx, fy, cx, cy), q=q, t=t, train=bool(roles & 1),
                        test=bool(roles & 2), labelled=bool(roles & 4), labels=None)
            p = plane(p, view, "rgb", w, h, 3)
            p = plane(p, view, "mask", w, h, 1)
            if has_labels:
                p = plane(p, view, "labels", w, h, 1)
            views.append(view)
        elif tag == b"PNTS":
            (count,) = struct.unpack_from("<Q", data, c)
            rows = list(struct.iter_unpack("<fffBBB", data[c + 8:c + 8 + 15 * count]))
            points = torch.tensor(rows, dtype=torch.float32)
        pos = nxt
    for (h, w), items in pending.items():  # version 3: every plane of one size decoded together
        decoded = med_decode(np.concatenate([planes for *_, planes in items]))
        k = 0
        for view, key, channels, _ in items:
            planes = decoded[k:k + channels].astype(np.int32)
            k += channels
            if channels == 3:  # G, R-G, B-G -> R, G, B
                g = planes[0]
                planes = np.stack([(planes[1] + g) % 256, g, (planes[2] + g) % 256])
            view[key] = torch.from_numpy(np.ascontiguousarray(planes.transpose(1, 2, 0)).astype(np.uint8))
    for v in views:
        v["mask"] = v["mask"][..., 0]
        if v["labels"] is not None:
            v["labels"] = v["labels"][..., 0]
    if not views or points is None or not classes:
        fail(path, "chunks", "CLAS, VIEW and PNTS chunks")
    return classes, views, points


def read_cache_once(path):
    """read_cache, keeping the decoded scene beside the cache (CACHE.decoded.pt) so that a second
    run on the same cache skips the pure-NumPy decode (~50-100 s for 70 views at 800x450). The copy
    is used only while it is newer than the cache."""
    import os
    copy = path + ".decoded.pt"
    try:
        if os.path.getmtime(copy) >= os.path.getmtime(path):
            return torch.load(copy)
    except Exception:  # missing, stale or unreadable: decode
        pass
    decoded = read_cache(path)
    try:
        torch.save(decoded, copy + ".tmp")
        os.replace(copy + ".tmp", copy)
    except Exception:  # a read-only folder or a type torch cannot save: decode again next time
        pass
    return decoded


def viewmat(v):
    w, x, y, z = v["q"]
    R = torch.tensor([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]],
                     dtype=torch.float64)
    m = torch.eye(4, dtype=torch.float64)
    m[:3, :3] = R
    m[:3, 3] = torch.tensor(v["t"], dtype=torch.float64)
    return m.float()


def intrinsics(v):
    fx, fy, cx, cy = v["K"]
    return torch.tensor([[fx, 0, cx], [0, fy, cy], [0, 0, 1]], dtype=torch.float32)


def scene_extent(viewmats):
    centres = torch.stack([-(m[:3, :3].T @ m[:3, 3]) for m in viewmats]).double()
    radius = (centres - centres.mean(0)).norm(dim=1).max().item()
    return max(1e-3, 1.1 * radius)


def knn_mean_distance(xyz, k=3, chunk=4096):
    out = torch.empty(len(xyz), device=xyz.device)
    for s in range(0, len(xyz), chunk):
        d = torch.cdist(xyz[s:s + chunk], xyz)
        out[s:s + chunk] = d.topk(k + 1, largest=False).values[:, 1:].mean(1)
    return out.clamp_min(1e-7)


def gaussian_window(size=11, sigma=1.5, device="cuda"):
    x = torch.arange(size, dtype=torch.float32, device=device) - size // 2
    g = torch.exp(-x * x / (2 * sigma * sigma))
    return g / g.sum()


def ssim(a, b, window):
    """SSIM of two [H, W, 3] images (valid-padding-free: zero padding, as the usual 3DGS code)."""
    x = a.permute(2, 0, 1).unsqueeze(0)
    y = b.permute(2, 0, 1).unsqueeze(0)
    k = window.numel()
    wh = window.view(1, 1, 1, k).expand(3, 1, 1, k)
    wv = window.view(1, 1, k, 1).expand(3, 1, k, 1)

    def blur(t):
        return F.conv2d(F.conv2d(t, wh, padding=(0, k // 2), groups=3), wv, padding=(k // 2, 0), groups=3)

    mx, my = blur(x), blur(y)
    sxx = blur(x * x) - mx * mx
    syy = blur(y * y) - my * my
    sxy = blur(x * y) - mx * my
    c1, c2 = 0.01 ** 2, 0.03 ** 2
    m = ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2))
    return m.mean()


def load_fused_ssim():
    """fused-ssim's CUDA extension, built just in time from its source (the package's own
    Python wrapper imports the module `fused_ssim_cuda`)."""
    import os
    from torch.utils.cpp_extension import load
    here = os.path.dirname(os.path.abspath(__file__))
    src = os.environ.get("FUSED_SSIM_SRC", os.path.join(here, "..", "..", ".deps", "fused-ssim"))
    if not os.path.isfile(os.path.join(src, "ssim.cu")):
        sys.exit(f"{src}: no fused-ssim source (ssim.cu); see scripts/gsplat_reference/README.md, "
                 "or pass --ssim torch")
    build = os.environ.get("FUSED_SSIM_BUILD", "/tmp/fused-ssim-ext")
    os.makedirs(build, exist_ok=True)
    module = load(name="fused_ssim_cuda", build_directory=build,
                  sources=[os.path.join(src, f) for f in ("ext.cpp", "ssim.cu", "ssim3d.cu")],
                  extra_cflags=["-O3", "-DFUSED_SSIM_CUDA"],
                  extra_cuda_cflags=["-O3", "-DFUSED_SSIM_CUDA", "--maxrregcount=32", "--use_fast_math"])
    sys.modules["fused_ssim_cuda"] = module
    sys.path.insert(0, src)
    from fused_ssim import fused_ssim
    return fused_ssim


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("cache")
    ap.add_argument("--iterations", type=int, default=7000)
    ap.add_argument("--features", type=int, default=32)
    ap.add_argument("--ssim-weight", type=float, default=0.2)
    ap.add_argument("--ssim", choices=["fused", "torch"], default="fused",
                    help="fused: fused-ssim's CUDA kernels (as gsplat's trainer); torch: convolutions")
    ap.add_argument("--seed", type=int, default=42)
    ap.add_argument("--packed", action="store_true", help="gsplat's packed mode")
    ap.add_argument("--json", help="write the results here")
    args = ap.parse_args()

    from gsplat import DefaultStrategy, rasterization, spherical_harmonics

    dev = torch.device("cuda")
    torch.manual_seed(args.seed)
    t_load = time.time()
    classes, views, pts = read_cache_once(args.cache)
    C = len(classes)
    vm = [viewmat(v) for v in views]
    extent = scene_extent(vm)
    train = [i for i, v in enumerate(views) if v["train"]]
    test = [i for i, v in enumerate(views) if v["test"] and v["labels"] is not None]
    labelled = [i for i in train if views[i]["labelled"] and views[i]["labels"] is not None]
    data = {}
    for i in train + test:
        v = views[i]
        mask = (v["mask"].to(dev) > 127)
        lab = None
        if v["labels"] is not None:
            lab = v["labels"].to(dev).long()
            lab = torch.where((lab != 255) & mask, lab, torch.full_like(lab, -1))
        data[i] = dict(rgb=v["rgb"].to(dev).float() / 255, mask=mask.float().unsqueeze(2),
                       labels=lab, viewmat=vm[i].to(dev)[None], K=intrinsics(v).to(dev)[None],
                       w=v["w"], h=v["h"])

    xyz = pts[:, :3].to(dev)
    rgb = pts[:, 3:].to(dev) / 255
    n = len(xyz)
    c0 = 0.28209479177387814
    sh = torch.zeros(n, 16, 3, device=dev)
    sh[:, 0] = (rgb - 0.5) / c0
    params = torch.nn.ParameterDict({
        "means": xyz,
        "scales": torch.log(knn_mean_distance(xyz)).unsqueeze(1).repeat(1, 3),
        "quats": torch.tensor([1.0, 0, 0, 0], device=dev).repeat(n, 1),
        "opacities": torch.full((n,), math.log(0.1 / 0.9), device=dev),
        "sh0": sh[:, :1].contiguous(),
        "shN": sh[:, 1:].contiguous(),
        "features": torch.randn(n, args.features, device=dev) * 0.01,
    }).to(dev)
    for p in params.values():
        p.requires_grad_(True)
    lrs = {"means": 1.6e-4 * extent, "scales": 5e-3, "quats": 1e-3, "opacities": 0.05,
           "sh0": 2.5e-3, "shN": 2.5e-3 / 20, "features": 2.5e-3}
    optimizers = {k: torch.optim.Adam([{"params": params[k], "lr": lr, "name": k}], eps=1e-15, fused=True)
                  for k, lr in lrs.items()}
    bound = 1 / math.sqrt(args.features)
    decoder = torch.nn.Linear(args.features, C).to(dev)
    with torch.no_grad():
        decoder.weight.uniform_(-bound, bound)
        decoder.bias.zero_()
    dec_opt = torch.optim.Adam(decoder.parameters(), lr=1e-3, eps=1e-15, fused=True)
    decay = (1.6e-6 / 1.6e-4) ** (1 / max(1, args.iterations))

    strategy = DefaultStrategy(refine_start_iter=500, refine_stop_iter=args.iterations // 2,
                               refine_every=100, reset_every=3000, grow_grad2d=2e-4,
                               grow_scale3d=0.01, prune_opa=0.005, prune_scale3d=0.1)
    strategy.check_sanity(params, optimizers)
    state = strategy.initialize_state(scene_scale=extent)
    window = gaussian_window(device=dev)
    ssim_of = lambda a, b: ssim(a, b, window)  # noqa: E731
    if args.ssim == "fused" and args.ssim_weight > 0:
        fused_ssim = load_fused_ssim()

        def ssim_of(a, b):  # [H, W, 3] images, the render first (fused-ssim differentiates only it)
            return fused_ssim(a.permute(2, 0, 1).unsqueeze(0), b.permute(2, 0, 1).unsqueeze(0), padding="same")

        probe = torch.Generator(device=dev).manual_seed(0)
        a = torch.rand(90, 160, 3, device=dev, generator=probe)
        b = (a + 0.1 * torch.rand(90, 160, 3, device=dev, generator=probe)).clamp(0, 1)
        a.requires_grad_(True)
        fused_value = ssim_of(a, b)
        (fused_grad,) = torch.autograd.grad(fused_value, a)
        torch_value = ssim(a, b, window)
        (torch_grad,) = torch.autograd.grad(torch_value, a)
        diff = abs(fused_value.item() - torch_value.item())
        grad_diff = ((fused_grad - torch_grad).abs().max() / torch_grad.abs().max()).item()
        print(f"fused SSIM vs torch SSIM on a test pair: |value difference| {diff:.2e}, "
              f"max gradient difference {grad_diff:.2e} of the largest", flush=True)
        if diff > 1e-4 or grad_diff > 1e-2:
            sys.exit("fused-ssim does not compute the SSIM defined here")
    gen = torch.Generator().manual_seed(args.seed)

    def render(i, degree, semantic):
        d = data[i]
        quats, scales = params["quats"], torch.exp(params["scales"])
        opac = torch.sigmoid(params["opacities"])
        coeffs = torch.cat([params["sh0"], params["shN"]], 1)
        if not semantic:
            img, alpha, info = rasterization(params["means"], quats, scales, opac, coeffs, d["viewmat"],
                                             d["K"], d["w"], d["h"], sh_degree=degree, packed=args.packed)
            return img[0], None, info
        colours = torch.clamp_min(spherical_harmonics(degree, params["means"], d["viewmat"], coeffs) + 0.5, 0.0)
        img, alpha, info = rasterization(params["means"], quats, scales, opac,
                                         torch.cat([colours, params["features"][None]], -1), d["viewmat"],
                                         d["K"], d["w"], d["h"], sh_degree=None, packed=args.packed,
                                         channel_chunk=64)  # one launch (default 32 splits 35 into 32 + 3)
        return img[0, ..., :3], img[0, ..., 3:], info

    def rgb_loss(i, image):
        d = data[i]
        m = d["mask"]
        l1 = ((image - d["rgb"]).abs() * m).mean()
        if args.ssim_weight <= 0:
            return l1
        return (1 - args.ssim_weight) * l1 + args.ssim_weight * (1 - ssim_of(image * m, d["rgb"] * m))

    def semantic_loss(i, feats):
        lab = data[i]["labels"]
        logits = decoder(feats)
        sup = lab >= 0
        cos = logits.gather(2, lab.clamp_min(0).unsqueeze(2)).squeeze(2) / logits.norm(dim=2).clamp_min(1e-8)
        return torch.where(sup, 1 - cos, torch.zeros_like(cos)).sum() / sup.sum().clamp_min(1)

    torch.cuda.synchronize()
    load_s = time.time() - t_load
    t0 = time.time()
    for it in range(args.iterations):
        degree = min(it // 1000, 3)
        tv = train[torch.randint(len(train), (1,), generator=gen).item()]
        image, _, info = render(tv, degree, False)
        strategy.step_pre_backward(params, optimizers, state, it + 1, info)
        loss = rgb_loss(tv, image)
        infos = []
        if labelled and it % 2 == 0:
            lv = labelled[torch.randint(len(labelled), (1,), generator=gen).item()]
            image2, feats, info2 = render(lv, degree, True)
            strategy.step_pre_backward(params, optimizers, state, it + 1, info2)
            loss = loss + rgb_loss(lv, image2) + semantic_loss(lv, feats)
            infos.append(info2)
        loss.backward()
        if it + 1 < strategy.refine_stop_iter:
            for extra in infos:  # densification statistics of the labelled view as well
                strategy._update_state(params, state, extra, packed=args.packed)
        for opt in list(optimizers.values()) + [dec_opt]:
            opt.step()
            opt.zero_grad(set_to_none=True)
        for g in optimizers["means"].param_groups:
            g["lr"] = lrs["means"] * decay ** (it + 1)
        strategy.step_post_backward(params, optimizers, state, it + 1, info, packed=args.packed)
        if (it + 1) % 1000 == 0:
            print(f"iteration {it + 1}: {len(params['means'])} Gaussians, {time.time() - t0:.1f} s",
                  flush=True)
    torch.cuda.synchronize()
    train_s = time.time() - t0

    # Evaluation on the test views (sadsplat's definitions: PSNR of the clamped render over the
    # whole image, mIoU over the classes present in prediction or ground truth).
    conf = torch.zeros(C, C, dtype=torch.long, device=dev)
    psnr = []
    with torch.no_grad():
        for i in test:
            image, feats, _ = render(i, 3, True)
            mse = ((image.clamp(0, 1) - data[i]["rgb"]) ** 2).mean().item()
            psnr.append(10 * math.log10(1 / max(mse, 1e-12)))
            pred = decoder(feats).argmax(2)
            lab = data[i]["labels"]
            ok = lab >= 0
            conf += torch.bincount(lab[ok] * C + pred[ok], minlength=C * C).view(C, C)
    tp = conf.diag().double()
    denom = conf.sum(0).double() + conf.sum(1).double() - tp
    present = denom > 0
    miou = (tp[present] / denom[present]).mean().item() if present.any() else float("nan")
    result = {"cache": args.cache, "iterations": args.iterations, "train_seconds": train_s,
              "load_seconds": load_s, "num_gaussians": len(params["means"]),
              "psnr": sum(psnr) / max(1, len(psnr)), "miou": miou, "ssim_weight": args.ssim_weight,
              "ssim": args.ssim if args.ssim_weight > 0 else "none",
              "packed": args.packed, "peak_memory_gb": torch.cuda.max_memory_allocated() / 2**30}
    print(json.dumps(result))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
