// The foundation-model backend (SAM + CLIP-family, TorchScript). The only translation unit that
// includes <torch/script.h> (heavy to compile).
#include "sadsplat/pseudo_labels/torchscript_scorer.h"

#include <torch/script.h>

#include <algorithm>
#include <numeric>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace pseudo_labels {
namespace {

torch::jit::Module loadModule(const std::string& path, const std::string& what) {
  if (!io::isRegularFile(path))
    throw Error(path, what + " model", "an existing TorchScript file", "missing");
  try {
    return torch::jit::load(path);
  } catch (const std::exception& e) {
    std::string msg = e.what();
    msg = msg.substr(0, msg.find('\n'));
    throw Error(path, what + " model", "a TorchScript file (torch.jit.save)", msg);
  }
}

void requireMethod(const torch::jit::Module& m, const std::string& path, const std::string& name) {
  if (!m.find_method(name))
    throw Error(path, "method " + name, "present (see torchscript_scorer.h)", "missing");
}

void requireAttribute(const torch::jit::Module& m, const std::string& path,
                      const std::string& name) {
  if (!m.hasattr(name))
    throw Error(path, "attribute " + name, "present (see torchscript_scorer.h)", "missing");
}

class TorchScriptScorer : public TargetScorer {
 public:
  TorchScriptScorer(const std::string& sam_path, const std::string& clip_path,
                    const MaskGenerationOptions& o)
      : sam_path_(sam_path), clip_path_(clip_path), options_(o) {
    if (o.device != "cpu" && o.device != "cuda")
      throw Error("<torchscript backend>", "device", "cpu or cuda", o.device);
    if (o.points_per_side < 1 || o.points_per_batch < 1) {
      throw Error("<torchscript backend>", "points_per_side / points_per_batch", "at least 1",
                  std::to_string(o.points_per_side) + " / " + std::to_string(o.points_per_batch));
    }
    device_ = o.device == "cuda" ? at::Device(at::kCUDA, 0) : at::Device(at::kCPU);
    sam_ = loadModule(sam_path, "SAM");
    clip_ = loadModule(clip_path, "CLIP");
    requireMethod(sam_, sam_path, "encode");
    requireMethod(sam_, sam_path, "decode");
    requireMethod(clip_, clip_path, "encode_image");
    for (const char* a : {"image_size", "logit_scale", "text_embeddings", "class_prompts"}) {
      requireAttribute(clip_, clip_path, a);
    }
    sam_.eval();
    clip_.eval();
    sam_.to(device_);
    clip_.to(device_);
  }

  std::string name() const override { return "torchscript"; }

  std::vector<ViewTargets> score(const io::Scene& scene, const std::vector<int>& views,
                                 const ProgressFn& progress) override {
    c10::InferenceMode guard;
    const at::Tensor text = textEmbeddings(scene);
    const double logit_scale = clip_.attr("logit_scale").toDouble();
    std::vector<ViewTargets> out;
    for (std::size_t k = 0; k < views.size(); ++k) {
      const io::View& v = scene.views[views[k]];
      out.push_back({{scoreView(v, text, logit_scale)}});
      if (progress) {
        progress("view " + std::to_string(k + 1) + "/" + std::to_string(views.size()) + " " +
                 v.name + ": " + std::to_string(out.back().layers[0].segmentation.num_regions) +
                 " SAM targets");
      }
    }
    return out;
  }

 private:
  at::Tensor textEmbeddings(const io::Scene& scene) const {
    const auto prompts = clip_.attr("class_prompts").toListRef();
    std::string theirs, ours;
    for (const auto& p : prompts) theirs += (theirs.empty() ? "" : ", ") + p.toStringRef();
    for (const auto& c : scene.classes) ours += (ours.empty() ? "" : ", ") + c.prompt;
    if (theirs != ours) {
      throw Error(clip_path_, "class_prompts",
                  "the scene's prompts [" + ours + "] (re-export with this classes.json)",
                  "[" + theirs + "]");
    }
    at::Tensor t = clip_.attr("text_embeddings").toTensor().to(device_, at::kFloat);
    if (t.dim() != 2 || t.size(0) != static_cast<std::int64_t>(scene.classes.size())) {
      throw Error(clip_path_, "text_embeddings",
                  "[C, E] with C = " + std::to_string(scene.classes.size()),
                  std::to_string(t.dim()) + "-d with " + std::to_string(t.size(0)) + " rows");
    }
    return t / t.norm(2, 1, true).clamp_min(1e-12);
  }

  TargetLayer scoreView(const io::View& v, const at::Tensor& text, double logit_scale) {
    const int W = v.camera.width, H = v.camera.height;
    const at::Tensor rgb =
        at::from_blob(const_cast<std::uint8_t*>(v.rgb.pixels.data()), {H, W, 3}, at::kByte)
            .to(device_)
            .permute({2, 0, 1})
            .unsqueeze(0)
            .to(at::kFloat);
    const at::Tensor valid =
        at::from_blob(const_cast<std::uint8_t*>(v.mask.pixels.data()), {H, W}, at::kByte)
            .to(device_) > 0;
    const auto embedding = sam_.get_method("encode")({rgb});

    // 1. Candidate masks from a grid of point prompts.
    struct Candidate {
      at::Tensor mask;
      float iou;
      std::array<float, 4> box;
      std::int64_t area;
    };
    std::vector<Candidate> candidates;
    const int n = options_.points_per_side;
    std::vector<float> grid;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        grid.push_back((i + 0.5f) * W / n);
        grid.push_back((j + 0.5f) * H / n);
      }
    }
    const std::int64_t total = n * n;
    for (std::int64_t b0 = 0; b0 < total; b0 += options_.points_per_batch) {
      const std::int64_t b = std::min<std::int64_t>(options_.points_per_batch, total - b0);
      const at::Tensor pts = at::from_blob(grid.data() + 2 * b0, {b, 2}, at::kFloat).to(device_);
      const auto result = sam_.get_method("decode")({embedding, pts, H, W});
      if (!result.isTuple() || result.toTupleRef().elements().size() != 2) {
        throw Error(sam_path_, "decode output",
                    "a tuple (mask logits [B, K, H, W], predicted IoU [B, K])",
                    result.isTuple() ? "a tuple of another size" : "not a tuple");
      }
      const at::Tensor logits = result.toTupleRef().elements()[0].toTensor().to(at::kFloat);
      const at::Tensor iou = result.toTupleRef().elements()[1].toTensor().to(at::kFloat).cpu();
      if (logits.dim() != 4 || logits.size(0) != b || logits.size(2) != H || logits.size(3) != W ||
          iou.dim() != 2 || iou.size(0) != b || iou.size(1) != logits.size(1)) {
        throw Error(sam_path_, "decode output shapes",
                    "[B, K, H, W] logits and [B, K] IoU with B = " + std::to_string(b) +
                        ", H x W = " + std::to_string(H) + " x " + std::to_string(W),
                    "logits " + std::to_string(logits.dim()) + "-d, IoU " +
                        std::to_string(iou.dim()) + "-d");
      }
      const double off = options_.stability_offset;
      const at::Tensor hi = (logits > off).flatten(2).sum(2).to(at::kFloat);
      const at::Tensor lo = (logits > -off).flatten(2).sum(2).to(at::kFloat);
      const at::Tensor stability = (hi / lo.clamp_min(1)).cpu();
      const at::Tensor masks = (logits > 0) & valid;
      const at::Tensor areas = masks.flatten(2).sum(2).cpu();
      for (std::int64_t i = 0; i < b; ++i) {
        for (std::int64_t k = 0; k < logits.size(1); ++k) {
          const float q = iou[i][k].item<float>();
          if (q < options_.pred_iou_threshold ||
              stability[i][k].item<float>() < options_.stability_threshold ||
              areas[i][k].item<std::int64_t>() < options_.min_mask_pixels) {
            continue;
          }
          const at::Tensor m = masks[i][k];
          const at::Tensor rows = m.any(1).nonzero().flatten(), cols = m.any(0).nonzero().flatten();
          Candidate c;
          c.mask = m.cpu();
          c.iou = q;
          c.area = areas[i][k].item<std::int64_t>();
          c.box = {static_cast<float>(cols.min().item<std::int64_t>()),
                   static_cast<float>(rows.min().item<std::int64_t>()),
                   static_cast<float>(cols.max().item<std::int64_t>()),
                   static_cast<float>(rows.max().item<std::int64_t>())};
          candidates.push_back(std::move(c));
        }
      }
    }

    // 2. NMS on boxes, then paint largest first so that smaller masks win where they overlap.
    std::vector<std::array<float, 4>> boxes;
    std::vector<float> scores;
    for (const auto& c : candidates) boxes.push_back(c.box), scores.push_back(c.iou);
    std::vector<int> kept = boxNms(boxes, scores, options_.box_nms_threshold);
    std::sort(kept.begin(), kept.end(),
              [&](int a, int b) { return candidates[a].area > candidates[b].area; });
    at::Tensor region = at::full({H, W}, -1, at::kInt);
    for (std::size_t t = 0; t < kept.size(); ++t) {
      region.masked_fill_(candidates[kept[t]].mask, static_cast<int>(t));
    }
    // Compact ids: drop targets painted over (or left with too few pixels).
    const at::Tensor counts =
        at::bincount(region.flatten().clamp_min(0), {}, static_cast<std::int64_t>(kept.size()) + 1);
    std::vector<std::int32_t> remap(kept.size() + 1, -1);
    int next = 0;
    for (std::size_t t = 0; t < kept.size(); ++t) {
      if (counts[t].item<std::int64_t>() >= options_.min_mask_pixels) remap[t] = next++;
    }
    TargetLayer vt;
    vt.segmentation.width = W;
    vt.segmentation.height = H;
    vt.segmentation.num_regions = next;
    vt.segmentation.region.resize(static_cast<std::size_t>(W) * H);
    const int* rp = region.data_ptr<int>();
    for (std::size_t i = 0; i < vt.segmentation.region.size(); ++i) {
      vt.segmentation.region[i] = rp[i] >= 0 ? remap[rp[i]] : -1;
    }
    vt.feature_dim = static_cast<int>(text.size(1));
    if (next == 0) return vt;

    // 3. Region embeddings: each target's box crop, outside the target greyed, resized to S x S.
    const std::int64_t S = clip_.attr("image_size").toInt();
    const at::Tensor ids =
        at::from_blob(vt.segmentation.region.data(), {H, W}, at::kInt).to(device_);
    const at::Tensor image01 = rgb[0] / 255.0;
    std::vector<at::Tensor> crops;
    for (int t = 0; t < next; ++t) {
      const at::Tensor m = ids == t;
      const at::Tensor rows = m.any(1).nonzero().flatten(), cols = m.any(0).nonzero().flatten();
      const std::int64_t y0 = rows.min().item<std::int64_t>(),
                         y1 = rows.max().item<std::int64_t>() + 1;
      const std::int64_t x0 = cols.min().item<std::int64_t>(),
                         x1 = cols.max().item<std::int64_t>() + 1;
      const at::Tensor crop = at::where(m.slice(0, y0, y1).slice(1, x0, x1).unsqueeze(0),
                                        image01.slice(1, y0, y1).slice(2, x0, x1),
                                        at::full({}, 0.5, image01.options()));
      crops.push_back(at::upsample_bilinear2d(crop.unsqueeze(0), {S, S}, false));
    }
    std::vector<at::Tensor> embeddings;
    for (std::size_t b0 = 0; b0 < crops.size(); b0 += 64) {
      const std::size_t b1 = std::min(crops.size(), b0 + 64);
      const at::Tensor batch =
          at::cat(std::vector<at::Tensor>(crops.begin() + b0, crops.begin() + b1), 0);
      const at::Tensor e = clip_.get_method("encode_image")({batch}).toTensor().to(at::kFloat);
      if (e.dim() != 2 || e.size(0) != batch.size(0) || e.size(1) != text.size(1)) {
        throw Error(clip_path_, "encode_image output",
                    "[B, E] with E = " + std::to_string(text.size(1)),
                    "[" + std::to_string(e.size(0)) + ", " +
                        std::to_string(e.dim() > 1 ? e.size(1) : 0) + "]");
      }
      embeddings.push_back(e);
    }
    at::Tensor image_emb = at::cat(embeddings, 0);
    image_emb = image_emb / image_emb.norm(2, 1, true).clamp_min(1e-12);
    const at::Tensor probs =
        at::softmax(logit_scale * at::matmul(image_emb, text.t()), 1).cpu().contiguous();
    const at::Tensor feats = image_emb.cpu().contiguous();
    vt.scores.assign(probs.data_ptr<float>(), probs.data_ptr<float>() + probs.numel());
    vt.features.assign(feats.data_ptr<float>(), feats.data_ptr<float>() + feats.numel());
    return vt;
  }

  std::string sam_path_, clip_path_;
  MaskGenerationOptions options_;
  at::Device device_{at::kCPU};
  torch::jit::Module sam_, clip_;
};

}  // namespace

std::vector<int> boxNms(const std::vector<std::array<float, 4>>& boxes,
                        const std::vector<float>& scores, double iou_threshold) {
  std::vector<int> order(boxes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return scores[a] > scores[b]; });
  auto area = [](const std::array<float, 4>& b) { return (b[2] - b[0] + 1) * (b[3] - b[1] + 1); };
  std::vector<int> kept;
  for (int i : order) {
    bool keep = true;
    for (int j : kept) {
      const float w = std::min(boxes[i][2], boxes[j][2]) - std::max(boxes[i][0], boxes[j][0]) + 1;
      const float h = std::min(boxes[i][3], boxes[j][3]) - std::max(boxes[i][1], boxes[j][1]) + 1;
      const float inter = std::max(0.0f, w) * std::max(0.0f, h);
      if (inter / (area(boxes[i]) + area(boxes[j]) - inter) > iou_threshold) {
        keep = false;
        break;
      }
    }
    if (keep) kept.push_back(i);
  }
  return kept;
}

TargetScorer::Ptr makeTorchScriptScorer(const std::string& sam_path, const std::string& clip_path,
                                        const MaskGenerationOptions& options) {
  return std::make_shared<TorchScriptScorer>(sam_path, clip_path, options);
}

}  // namespace pseudo_labels
}  // namespace sadsplat
