// Elementwise kernels over a flat range of `count` elements. Tensor arguments follow the
// library's convention: (buffer, element offset). Every kernel guards its index, so the host
// may round the global size up to a multiple of the work-group size.

__kernel void fill(__global float* restrict out, const int out_offset, const int count, const float value) {
  const int i = get_global_id(0);
  if (i >= count) return;
  out[out_offset + i] = value;
}

// out = alpha * a + beta * b (a and out may alias).
__kernel void axpby(__global float* out, const int out_offset,
                    __global const float* a, const int a_offset,
                    __global const float* b, const int b_offset,
                    const int count, const float alpha, const float beta) {
  const int i = get_global_id(0);
  if (i >= count) return;
  out[out_offset + i] = alpha * a[a_offset + i] + beta * b[b_offset + i];
}

// out = alpha * a (in place allowed).
__kernel void scale(__global float* out, const int out_offset,
                    __global const float* a, const int a_offset,
                    const int count, const float alpha) {
  const int i = get_global_id(0);
  if (i >= count) return;
  out[out_offset + i] = alpha * a[a_offset + i];
}
