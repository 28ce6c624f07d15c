#!/usr/bin/env python3
"""Export SAM and a CLIP-family model (e.g. GeoRSCLIP, an open_clip ViT-B/32 or ViT-H/14
checkpoint) to the TorchScript files `sadsplat pseudo-labels --backend torchscript` loads. The
contract is documented in modules/pseudo_labels/include/sadsplat/pseudo_labels/torchscript_scorer.h.

Run where the weights and packages can be downloaded (pip install torch segment-anything open_clip_torch):
  python3 scripts/export_foundation_models.py --sam-checkpoint sam_vit_b_01ec64.pth --sam-type vit_b \
      --clip-model ViT-B-32 --clip-checkpoint RS5M_ViT-B-32.pt --classes SCENE/classes.json --out models/
The text side is encoded here, for the prompts of that classes.json (C++ needs no tokenizer).

NOT RUN where this project is developed (no internet there): written against the public APIs of
segment_anything and open_clip; the C++ side is tested only with the tiny models of
scripts/make_tiny_foundation_models.py."""
import argparse
import json
from typing import List, Tuple

import torch
import torch.nn.functional as F
from torch import nn


class SamExport(nn.Module):
    def __init__(self, sam):
        super().__init__()
        self.sam = sam
        self.size = sam.image_encoder.img_size  # 1024

    @torch.jit.export
    def encode(self, image: torch.Tensor) -> torch.Tensor:
        # image [1, 3, H, W] RGB 0..255 -> longest side to 1024, normalise, pad (SAM's preprocessing).
        H, W = image.shape[-2], image.shape[-1]
        s = float(self.size) / float(max(H, W))
        x = F.interpolate(image, size=(int(H * s + 0.5), int(W * s + 0.5)), mode="bilinear", align_corners=False)
        x = self.sam.preprocess(x[0]).unsqueeze(0)
        return self.sam.image_encoder(x)

    @torch.jit.export
    def decode(self, embedding: torch.Tensor, points: torch.Tensor, H: int, W: int) -> Tuple[torch.Tensor, torch.Tensor]:
        s = float(self.size) / float(max(H, W))
        coords = (points * s).unsqueeze(1)  # [B, 1, 2]
        labels = torch.ones(points.shape[0], 1, dtype=torch.int, device=points.device)
        sparse, dense = self.sam.prompt_encoder(points=(coords, labels), boxes=None, masks=None)
        low, iou = self.sam.mask_decoder(image_embeddings=embedding, image_pe=self.sam.prompt_encoder.get_dense_pe(),
                                         sparse_prompt_embeddings=sparse, dense_prompt_embeddings=dense,
                                         multimask_output=True)
        masks = F.interpolate(low, size=(self.size, self.size), mode="bilinear", align_corners=False)
        masks = masks[..., : int(H * s + 0.5), : int(W * s + 0.5)]
        return F.interpolate(masks, size=(H, W), mode="bilinear", align_corners=False), iou


class ClipExport(nn.Module):
    def __init__(self, model, text_embeddings: torch.Tensor, prompts: List[str], image_size: int, logit_scale: float):
        super().__init__()
        self.visual = model.visual
        self.image_size = image_size
        self.logit_scale = logit_scale
        self.class_prompts: List[str] = prompts
        self.text_embeddings = nn.Parameter(text_embeddings, requires_grad=False)
        self.register_buffer("mean", torch.tensor([0.48145466, 0.4578275, 0.40821073]).view(1, 3, 1, 1))
        self.register_buffer("std", torch.tensor([0.26862954, 0.26130258, 0.27577711]).view(1, 3, 1, 1))

    @torch.jit.export
    def encode_image(self, images: torch.Tensor) -> torch.Tensor:
        return self.visual((images - self.mean) / self.std)

    def forward(self, images: torch.Tensor) -> torch.Tensor:
        return self.encode_image(images)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sam-checkpoint", required=True)
    ap.add_argument("--sam-type", default="vit_b")
    ap.add_argument("--clip-model", default="ViT-B-32")
    ap.add_argument("--clip-checkpoint", required=True)
    ap.add_argument("--classes", required=True, help="the scene's classes.json (prompts)")
    ap.add_argument("--out", default=".")
    a = ap.parse_args()
    from segment_anything import sam_model_registry
    import open_clip

    sam = sam_model_registry[a.sam_type](checkpoint=a.sam_checkpoint).eval()
    torch.jit.save(torch.jit.script(SamExport(sam)), f"{a.out}/sam.pt")

    model, _, _ = open_clip.create_model_and_transforms(a.clip_model, pretrained=a.clip_checkpoint)
    model.eval()
    classes = json.load(open(a.classes))["classes"]
    prompts = [c.get("prompt", c["name"]) for c in classes]
    with torch.no_grad():
        text = model.encode_text(open_clip.get_tokenizer(a.clip_model)(prompts)).float()
    size = model.visual.image_size
    size = size[0] if isinstance(size, (tuple, list)) else size
    clip = ClipExport(model, text, prompts, int(size), float(model.logit_scale.exp().item()))
    torch.jit.save(torch.jit.script(clip), f"{a.out}/clip.pt")
    print(f"wrote {a.out}/sam.pt and {a.out}/clip.pt for prompts {prompts}")


if __name__ == "__main__":
    main()
