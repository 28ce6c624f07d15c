// Warp-level matrix products on tensor cores for the rasterizer's channel sums: mma.sync
// m16n8k8 with TF32 inputs and FP32 accumulation, in the "3xTF32" form that keeps FP32 accuracy.
// A float x is split into a TF32 head h = tf32(x) and tail l = tf32(x - h); a * b is taken as
// a_l b_h + a_h b_l + a_h b_h (the a_l b_l term, ~2^-22 relative, is dropped). One TF32 product
// alone would leave ~1e-3 relative error in a rendered pixel; three keep renders and gradients
// within the CPU reference's float tolerances.
//
// Fragment layout of m16n8k8 (PTX ISA, "Matrix fragments for mma.m16n8k8", .tf32), per lane with
// group = lane / 4 and quad = lane % 4:
//   A (16 x 8, row major):  a0 (group, quad)  a1 (group + 8, quad)
//                           a2 (group, quad + 4)  a3 (group + 8, quad + 4)
//   B (8 x 8, column major): b0 (quad, group)  b1 (quad + 4, group)
//   C, D (16 x 8):           c0 (group, 2 quad)  c1 (group, 2 quad + 1)
//                           c2 (group + 8, 2 quad)  c3 (group + 8, 2 quad + 1)
// Internal to the CUDA rasterizer (included by raster_cuda.cu only).
#pragma once

#include <cstdint>

#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ < 800
#error "sadsplat's CUDA rasterizer uses TF32 tensor cores: compute capability 8.0 or newer"
#endif

namespace sadsplat {
namespace gaussians {
namespace raster {

// A float split into its TF32 head and tail (bit patterns, as mma takes them).
struct Tf32Split {
  std::uint32_t head, tail;
};

__device__ __forceinline__ std::uint32_t toTf32(float x) {
  std::uint32_t r;
  asm("cvt.rna.tf32.f32 %0, %1;" : "=r"(r) : "f"(x));
  return r;
}

__device__ __forceinline__ Tf32Split splitTf32(float x) {
  const std::uint32_t head = toTf32(x);
  return {head, toTf32(x - __uint_as_float(head))};
}

// d += a * b for one m16n8k8 tile, TF32 inputs (one product, no split).
__device__ __forceinline__ void mmaTf32(float (&d)[4], std::uint32_t a0, std::uint32_t a1,
                                        std::uint32_t a2, std::uint32_t a3, std::uint32_t b0,
                                        std::uint32_t b1) {
  asm("mma.sync.aligned.m16n8k8.row.col.f32.tf32.tf32.f32 {%0, %1, %2, %3}, {%4, %5, %6, %7}, "
      "{%8, %9}, {%0, %1, %2, %3};"
      : "+f"(d[0]), "+f"(d[1]), "+f"(d[2]), "+f"(d[3])
      : "r"(a0), "r"(a1), "r"(a2), "r"(a3), "r"(b0), "r"(b1));
}

// d += a * b with split operands (3xTF32): the two small cross terms first.
__device__ __forceinline__ void mma3xTf32(float (&d)[4], const Tf32Split (&a)[4],
                                          const Tf32Split (&b)[2]) {
  mmaTf32(d, a[0].tail, a[1].tail, a[2].tail, a[3].tail, b[0].head, b[1].head);
  mmaTf32(d, a[0].head, a[1].head, a[2].head, a[3].head, b[0].tail, b[1].tail);
  mmaTf32(d, a[0].head, a[1].head, a[2].head, a[3].head, b[0].head, b[1].head);
}

}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
