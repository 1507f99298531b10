// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the kernels. A kernel file includes this one by name; the build
// (cmake/EmbedKernels.cmake) replaces that line by this file's text, so the program cache key, a
// hash of the embedded source, changes whenever this file does.

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
