#!/usr/bin/python3
"""Tiny, randomly initialised TorchScript models with the interfaces of the exported SAM and
CLIP files (see modules/pseudo_labels/include/sadsplat/pseudo_labels/torchscript_scorer.h), for
the tests of the torchscript backend. Runs with Debian's python3-torch (1.13); the files are
committed under data/models/ so that the tests need no Python.

  /usr/bin/python3 scripts/make_tiny_foundation_models.py data/models

The "SAM" embeds 4x4 patches with a fixed averaging convolution plus a small random one; a point
prompt's masks are the pixels whose embedding is close to the embedding under the point, at
three thresholds (SAM's three multimask outputs); the predicted IoU is a random linear function
of the point's embedding. The "CLIP" pools the crop and maps it with a random linear layer; its
text embeddings are random vectors for the prompts "red", "green", "blue" (the toy scene of the
tests)."""
import sys
from typing import List, Tuple

import torch
import torch.nn.functional as F
from torch import nn


class TinySam(nn.Module):
    def __init__(self):
        super().__init__()
        self.patch = nn.Conv2d(3, 8, 4, stride=4)
        with torch.no_grad():
            self.patch.weight.mul_(0.1)
            for c in range(3):  # channels 0..2: the patch's mean colour
                self.patch.weight[c].zero_()
                self.patch.weight[c, c].fill_(1.0 / 16)
                self.patch.bias[c] = 0.0
        self.iou_head = nn.Linear(8, 3)
        self.scales = nn.Parameter(torch.tensor([40.0, 20.0, 10.0]))

    @torch.jit.export
    def encode(self, image: torch.Tensor) -> torch.Tensor:
        return self.patch(image / 255.0 - 0.5)

    @torch.jit.export
    def decode(self, embedding: torch.Tensor, points: torch.Tensor, H: int, W: int) -> Tuple[torch.Tensor, torch.Tensor]:
        emb = F.interpolate(embedding, size=(H, W), mode="bilinear", align_corners=False)[0]  # [8, H, W]
        xs = points[:, 0].clamp(0, W - 1).long()
        ys = points[:, 1].clamp(0, H - 1).long()
        at_point = emb[:, ys, xs].t()  # [B, 8]
        dist = ((emb.unsqueeze(0) - at_point[:, :, None, None]) ** 2)[:, :3].sum(1)  # colour distance [B, H, W]
        logits = 4.0 - dist.unsqueeze(1) * self.scales[None, :, None, None] * 100.0  # [B, 3, H, W]
        iou = torch.sigmoid(self.iou_head(at_point))
        return logits, iou


class TinyClip(nn.Module):
    def __init__(self, prompts: List[str], dim: int = 16):
        super().__init__()
        self.proj = nn.Linear(3, dim)
        self.image_size = 32
        self.logit_scale = 100.0
        self.class_prompts: List[str] = prompts
        self.text_embeddings = nn.Parameter(torch.randn(len(prompts), dim), requires_grad=False)

    @torch.jit.export
    def encode_image(self, images: torch.Tensor) -> torch.Tensor:
        return self.proj(images.mean(dim=(2, 3)))

    def forward(self, images: torch.Tensor) -> torch.Tensor:
        return self.encode_image(images)


def main() -> None:
    out = sys.argv[1] if len(sys.argv) > 1 else "data/models"
    torch.manual_seed(0)
    torch.jit.save(torch.jit.script(TinySam().eval()), f"{out}/tiny_sam.pt")
    torch.jit.save(torch.jit.script(TinyClip(["red", "green", "blue"]).eval()), f"{out}/tiny_clip.pt")
    print(f"wrote {out}/tiny_sam.pt and {out}/tiny_clip.pt")


if __name__ == "__main__":
    main()
