// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the kernels. A kernel file includes this one by name; the build
// (cmake/EmbedKernels.cmake) replaces that line by this file's text, so the program cache key, a
// hash of the embedded source, changes whenever this file does.

// On a CPU without AVX-512, clang warns at every call of a builtin (fma, vload16, shuffle2, …)
// with a float16 argument or result that passing it "changes the ABI" (-Wpsabi), and PoCL prints
// each warning on the user's terminal at a first run: 490 of them for FlowNet2. The warning is
// about linking code built for other CPU features; PoCL builds the kernel and its builtin library
// for the same CPU, so it cannot apply. Only this warning is silenced (the tests keep the kernels
// free of every other: testing::expect_held_kernels_compile_without_warnings).
#ifdef __clang__
#pragma clang diagnostic ignored "-Wpsabi"
#endif

// The fused activation, chosen by build options (see include/inertialnet/ops/activation.hpp):
//   -DACTIVATION=0 none, 1 ReLU (v < 0 ? 0 : v, NaN kept), 2 LeakyReLU (v < 0 ? s·v : v)
//   -DNEGATIVE_SLOPE=<s>f
// The selections work on scalars and on vectors alike (a vector condition selects per lane).
#ifndef ACTIVATION
#define ACTIVATION 0
#endif
#ifndef NEGATIVE_SLOPE
#define NEGATIVE_SLOPE 0.1f
#endif

#if ACTIVATION == 1
#define ACTIVATE(v) ((v) < 0.0f ? 0.0f : (v))
#elif ACTIVATION == 2
#define ACTIVATE(v) ((v) < 0.0f ? (v) * NEGATIVE_SLOPE : (v))
#else
#define ACTIVATE(v) (v)
#endif

// Sums scratch[0..size) into scratch[0] (size a power of two: the work-group size), pairing the
// halves in a fixed order, so one work-group size always gives one result (no float atomics).
// Every work-item of the group calls it after writing its own scratch[lane]; when it returns,
// scratch[0] holds the sum for all of them.
inline void work_group_tree_sum(__local float* scratch, const int lane, const int size) {
  for (int span = size / 2; span > 0; span /= 2) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lane < span) scratch[lane] += scratch[lane + span];
  }
  barrier(CLK_LOCAL_MEM_FENCE);
}
