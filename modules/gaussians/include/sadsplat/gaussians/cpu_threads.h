#pragma once
/// \file cpu_threads.h
/// \brief How many threads the CPU backend (and LibTorch's CPU operators) use.

namespace sadsplat {
namespace gaussians {

/// \brief Sets LibTorch's intra-op CPU threads and returns the count in use: `threads` when
/// > 0, else OMP_NUM_THREADS when set, else one per core. Debian's LibTorch 1.13 starts with one
/// thread whatever the machine, so programs call this once at start.
int setCpuThreads(int threads = 0);

}  // namespace gaussians
}  // namespace sadsplat
