// Four doubles as one GCC vector (the hot loops of the demodulator chain: the 4-channel filter and
// the batch validator; the batch least-squares kernels), with unaligned load and store, and
// CVG_HOT_CLONES to compile a function also for x86-64-v3 (AVX2/FMA) with dispatch at load time.
// Portable: the default clone is plain x86-64.
#pragma once

#include <cstring>

// The vectors never cross an ABI boundary: every helper taking or returning a V4 by value is
// always_inline. An out-of-line copy (-O0, or the inliner declining) is compiled for the default
// target and returns the vector in memory, while a CVG_HOT_CLONES caller built for x86-64-v3
// expects it in a ymm register: at -O0 the validator read through a garbage pointer.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace cvg_bench {
namespace simd {

using V4 = double __attribute__((vector_size(32)));

__attribute__((always_inline)) inline V4 load4(const double* p) {
  V4 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

__attribute__((always_inline)) inline void store4(double* p, const V4& v) {
  std::memcpy(p, &v, sizeof(v));
}

}  // namespace simd
}  // namespace cvg_bench

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
#define CVG_HOT_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define CVG_HOT_CLONES
#endif
