// The geometric head's reductions (include/inertialnet/models/geometric_head.hpp defines the
// quantities; src/models/geometric_head.cpp iterates them).
//
// Both kernels visit a strided grid of flow vectors. Per sample: the two ends of the flow
// vector are mapped to undistorted normalised coordinates through the per-pixel coordinate map
// (bilinear at the far end), the model uses their midpoint and their difference over dt.
//
// Build options: -DWG_SIZE=<power of two> always; moments also takes -DMODE=<0 rotation |
// 1 general> and -DLOSS=<0 least squares | 1 Huber | 2 Cauchy | 3 Tukey>.

#ifndef WG_SIZE
#define WG_SIZE 64
#endif
#ifndef MODE
#define MODE 0
#endif
#ifndef LOSS
#define LOSS 0
#endif

#define UNKNOWN_FLOW 1e9f
// The normalisation 1/|n|² of the general mode is capped at 1/N2_FLOOR (|n| ≥ 0.1, i.e. within
// ≈6° of the focus of expansion) so that a few pixels there cannot dominate the quadratic form.
#define N2_FLOOR 1e-2f

// Bilinear lookup of both coordinate planes at (px, py), which the caller checked lies within
// [0, W−1] × [0, H−1]. The cell is clamped so that the last row and column still have four
// neighbours (their weight on the far side is then zero).
inline float2 map_at(__global const float* restrict map, const int map_offset, const int width, const int height,
                     const float px, const float py) {
  const int x0 = min((int)px, width - 2);
  const int y0 = min((int)py, height - 2);
  const float fx = px - (float)x0;
  const float fy = py - (float)y0;
  const int plane = width * height;
  const int i = map_offset + y0 * width + x0;
  const float x = (1.0f - fy) * ((1.0f - fx) * map[i] + fx * map[i + 1]) +
                  fy * ((1.0f - fx) * map[i + width] + fx * map[i + width + 1]);
  const float y = (1.0f - fy) * ((1.0f - fx) * map[plane + i] + fx * map[plane + i + 1]) +
                  fy * ((1.0f - fx) * map[plane + i + width] + fx * map[plane + i + width + 1]);
  return (float2)(x, y);
}

// The normalised ends of grid sample `s`; false when the flow is unknown or leaves the image.
inline bool sample_ends(__global const float* restrict flow, const int flow_offset,
                        __global const float* restrict map, const int map_offset,
                        const int width, const int height, const int stride, const int first,
                        const int columns, const int s, float2* p1, float2* p2) {
  const int u = first + (s % columns) * stride;
  const int v = first + (s / columns) * stride;
  const int pixel = v * width + u;
  const float du = flow[flow_offset + pixel];
  const float dv = flow[flow_offset + width * height + pixel];
  // The negated comparisons are also true for NaN.
  if (!(fabs(du) <= UNKNOWN_FLOW) || !(fabs(dv) <= UNKNOWN_FLOW)) return false;
  const float qx = (float)u + du;
  const float qy = (float)v + dv;
  if (!(qx >= 0.0f && qx <= (float)(width - 1) && qy >= 0.0f && qy <= (float)(height - 1))) return false;
  const int plane = width * height;
  *p1 = (float2)(map[map_offset + pixel], map[map_offset + plane + pixel]);
  *p2 = map_at(map, map_offset, width, height, qx, qy);
  return true;
}

inline float robust_weight(const float e, const float inv_scale) {
#if LOSS == 1
  const float t = e * inv_scale;
  return t <= 1.0f ? 1.0f : 1.0f / t;
#elif LOSS == 2
  const float t = e * inv_scale;
  return 1.0f / (1.0f + t * t);
#elif LOSS == 3
  const float t = e * inv_scale * (1.0f / 4.685f);
  const float a = 1.0f - t * t;
  return t < 1.0f ? a * a : 0.0f;
#else
  return 1.0f;
#endif
}

#if MODE == 1
#define NQ 92  // gram[78], metric[6], then the diagnostics
#define DIAG 84
#else
#define NQ 15  // normal[6], rhs[3], then the diagnostics
#define DIAG 9
#endif

// Mᵀ·(ax, ay) with M = [[0, 1, −y], [−1, 0, x]].
#define M_TRANSPOSE(v, k, ax_, ay_) \
  v[k] = -(ay_);                    \
  v[k + 1] = (ax_);                 \
  v[k + 2] = x * (ay_) - y * (ax_);

// The loss itself (its derivative over e is robust_weight): e²/2 (least squares), Huber's
// e²/2 | σ(e − σ/2), Cauchy's σ²/2·ln(1 + (e/σ)²), Tukey's c²/6·(1 − (1 − (e/c)²)³) | c²/6.
inline float robust_loss(const float e, const float inv_scale) {
#if LOSS == 1
  const float sigma = 1.0f / inv_scale;
  return e <= sigma ? 0.5f * e * e : sigma * (e - 0.5f * sigma);
#elif LOSS == 2
  const float sigma = 1.0f / inv_scale;
  const float t = e * inv_scale;
  return 0.5f * sigma * sigma * log(1.0f + t * t);
#elif LOSS == 3
  const float c = 4.685f / inv_scale;
  const float t = e / c;
  const float a = 1.0f - t * t;
  return t < 1.0f ? c * c / 6.0f * (1.0f - a * a * a) : c * c / 6.0f;
#else
  return 0.5f * e * e;
#endif
}

// Work-group partial sums of MotionFieldMoments into partial[partial_offset + group·NQ + q]:
// rotation mode: normal[6], rhs[3]; general mode: gram[78] (upper triangle, row by row),
// metric[6]; then weight_sum, weighted_sq_residual, inliers, inlier_sq_residual, usable,
// loss_sum (and in general mode parallel_sum, parallel_sq). Each work-item sums a few samples in float (the
// grid is spread over all work-items), the group adds its work-items in a tree, and the host
// adds the groups in double.
__kernel __attribute__((reqd_work_group_size(WG_SIZE, 1, 1)))
void moments(__global const float* restrict flow, const int flow_offset,
             __global const float* restrict map, const int map_offset,
             const int width, const int height, const int stride, const int first, const int columns,
             const int samples, const float inv_dt,
             const float wx, const float wy, const float wz,
             const float tx, const float ty, const float tz,
             const float inv_scale, const float inlier_threshold,
             __global float* restrict partial, const int partial_offset) {
  float acc[NQ];
  for (int q = 0; q < NQ; ++q) acc[q] = 0.0f;
#if MODE == 1
  const bool have_t = tx != 0.0f || ty != 0.0f || tz != 0.0f;
#endif

  for (int s = get_global_id(0); s < samples; s += get_global_size(0)) {
    float2 p1, p2;
    if (!sample_ends(flow, flow_offset, map, map_offset, width, height, stride, first, columns, s, &p1, &p2)) continue;
    const float x = 0.5f * (p1.x + p2.x);
    const float y = 0.5f * (p1.y + p2.y);
    const float bx = (p2.x - p1.x) * inv_dt;
    const float by = (p2.y - p1.y) * inv_dt;
    // The columns of A(x, y) (docs/data_conventions.md): ẋ = ax·ω, ẏ = ay·ω.
    const float ax0 = x * y, ax1 = -(1.0f + x * x), ax2 = y;
    const float ay0 = 1.0f + y * y, ay1 = -x * y, ay2 = -x;
    const float rx = bx - (ax0 * wx + ax1 * wy + ax2 * wz);
    const float ry = by - (ay0 * wx + ay1 * wy + ay2 * wz);
    acc[DIAG + 4] += 1.0f;

#if MODE == 1
    float e, psi, w;
    float hx = 0.0f, hy = 0.0f;
    if (have_t) {
      const float nx = ty - y * tz;  // n = M·T
      const float ny = x * tz - tx;
      const float n2 = nx * nx + ny * ny;
      if (n2 < 1e-12f) continue;  // at the focus of expansion: no constraint
      const float inv_n = rsqrt(n2);
      hx = nx * inv_n;
      hy = ny * inv_n;
      e = fabs(hx * rx + hy * ry);
      psi = robust_weight(e, inv_scale);
      w = psi / fmax(n2, N2_FLOOR);
    } else {
      e = sqrt(rx * rx + ry * ry);
      psi = robust_weight(e, inv_scale);
      w = psi;
    }
    float v[12];
    M_TRANSPOSE(v, 0, ax0, ay0)
    M_TRANSPOSE(v, 3, ax1, ay1)
    M_TRANSPOSE(v, 6, ax2, ay2)
    M_TRANSPOSE(v, 9, rx, ry)
    int k = 0;
    for (int i = 0; i < 12; ++i) {
      const float wv = w * v[i];
      for (int j = i; j < 12; ++j) acc[k++] += wv * v[j];
    }
    acc[78] += w; acc[80] -= w * x;  // MᵀM = [[1, 0, −x], [0, 1, −y], [−x, −y, x² + y²]]
    acc[81] += w; acc[82] -= w * y; acc[83] += w * (x * x + y * y);
    acc[DIAG] += psi;
    acc[DIAG + 1] += psi * e * e;
    acc[DIAG + 5] += robust_loss(e, inv_scale);
    if (e < inlier_threshold) {
      acc[DIAG + 2] += 1.0f;
      acc[DIAG + 3] += e * e;
      if (have_t) {
        const float par = hy * rx - hx * ry;  // d̂ = (n̂y, −n̂x)
        acc[DIAG + 6] += par;
        acc[DIAG + 7] += par * par;
      }
    }
#else
    const float e = sqrt(rx * rx + ry * ry);
    const float w = robust_weight(e, inv_scale);
    acc[0] += w * (ax0 * ax0 + ay0 * ay0); acc[1] += w * (ax0 * ax1 + ay0 * ay1);
    acc[2] += w * (ax0 * ax2 + ay0 * ay2); acc[3] += w * (ax1 * ax1 + ay1 * ay1);
    acc[4] += w * (ax1 * ax2 + ay1 * ay2); acc[5] += w * (ax2 * ax2 + ay2 * ay2);
    acc[6] += w * (ax0 * bx + ay0 * by); acc[7] += w * (ax1 * bx + ay1 * by); acc[8] += w * (ax2 * bx + ay2 * by);
    acc[DIAG] += w;
    acc[DIAG + 1] += w * e * e;
    acc[DIAG + 5] += robust_loss(e, inv_scale);
    if (e < inlier_threshold) {
      acc[DIAG + 2] += 1.0f;
      acc[DIAG + 3] += e * e;
    }
#endif
  }

  // One tree over all quantities at once: NQ·WG_SIZE floats of local memory (the host picks
  // WG_SIZE so that it fits).
  __local float scratch[NQ * WG_SIZE];
  const int lid = get_local_id(0);
  for (int q = 0; q < NQ; ++q) scratch[q * WG_SIZE + lid] = acc[q];
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int width_half = WG_SIZE / 2; width_half > 0; width_half >>= 1) {
    if (lid < width_half) {
      for (int q = 0; q < NQ; ++q) scratch[q * WG_SIZE + lid] += scratch[q * WG_SIZE + lid + width_half];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  for (int q = lid; q < NQ; q += WG_SIZE) partial[partial_offset + get_group_id(0) * NQ + q] = scratch[q * WG_SIZE];
}

// The grid samples as normalised correspondences (x1, y1, x2, y2) in out[out_offset + 4·s];
// unusable samples get NaN in all four.
__kernel void correspondences(__global const float* restrict flow, const int flow_offset,
                              __global const float* restrict map, const int map_offset,
                              const int width, const int height, const int stride, const int first,
                              const int columns, const int samples,
                              __global float* restrict out, const int out_offset) {
  const int s = get_global_id(0);
  if (s >= samples) return;
  float2 p1, p2;
  const int o = out_offset + 4 * s;
  if (sample_ends(flow, flow_offset, map, map_offset, width, height, stride, first, columns, s, &p1, &p2)) {
    out[o] = p1.x; out[o + 1] = p1.y; out[o + 2] = p2.x; out[o + 3] = p2.y;
  } else {
    out[o] = out[o + 1] = out[o + 2] = out[o + 3] = NAN;
  }
}
