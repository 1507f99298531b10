// SPDX-License-Identifier: Apache-2.0
// Optical flow on the host: the Middlebury `.flo` file format and the Middlebury colour coding.
//
// `.flo` (Baker et al., "A Database and Evaluation Methodology for Optical Flow"): the float
// 202021.25 (bytes "PIEH"), int32 width, int32 height, then width·height (u, v) float32 pairs,
// row-major, all little-endian. Vectors with |u| or |v| above 1e9 (or NaN) mean "unknown flow";
// the file functions keep them bit for bit, the colour coding paints them black.
//
// Colour coding: the direction picks a hue on Middlebury's 55-colour wheel (red for +u, i.e.
// motion to the right; the hue turns through yellow, green, cyan, blue and magenta), the
// magnitude divided by a normalising radius the saturation: zero flow is white, flow at the
// radius is the fully saturated wheel colour, flow beyond it the wheel colour dimmed to 75 %.
//
// KITTI flow PNG (Geiger et al., KITTI 2012/2015 devkit): a 16-bit, 3-channel PNG whose red
// channel holds u and green v as (value − 2^15) / 64 pixels, and whose blue channel is 1 where
// the flow is valid and 0 where it is not; the precision is 1/64 px and the range ±512 px.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace inertialnet {

// Middlebury's threshold: flow with |u| or |v| above it (or NaN) is unknown.
constexpr float kUnknownFlowThreshold = 1e9f;
// The value Middlebury writes for unknown flow.
constexpr float kUnknownFlowValue = 1e10f;

bool is_unknown_flow(float u, float v);

// A dense flow field in pixels: u along x (right), v along y (down). Stored as two planes, like
// the two channels of the network's flow tensor, each row-major with `width` floats per row.
struct FlowField {
  int width = 0;
  int height = 0;
  std::vector<float> u;
  std::vector<float> v;

  FlowField() = default;
  // Zero flow of the given size; throws invalid_input unless both sizes are positive.
  FlowField(int width, int height);
  // From the [2, H, W] layout of a downloaded flow tensor (u plane, then v plane).
  static FlowField from_planar(int width, int height, const std::vector<float>& uv_planes);

  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  std::size_t index(int x, int y) const { return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x); }
  float& u_at(int x, int y) { return u[index(x, y)]; }
  float& v_at(int x, int y) { return v[index(x, y)]; }
  float u_at(int x, int y) const { return u[index(x, y)]; }
  float v_at(int x, int y) const { return v[index(x, y)]; }

  // Throws invalid_input unless the sizes are positive and both planes hold width·height values.
  void validate() const;
};

// Throws invalid_input naming the file for a missing or unreadable file, a wrong magic number,
// non-positive or absurd (> 100000) sizes, or data shorter or longer than width·height·8 bytes.
FlowField read_flo(const std::filesystem::path& path);

// Writes to a temporary file beside `path`, then renames it into place, so a reader never sees a
// half-written file. A missing folder or a read-only location is invalid_input.
void write_flo(const std::filesystem::path& path, const FlowField& flow);

// KITTI flow PNG. Invalid pixels read back as unknown flow (kUnknownFlowValue). Throws
// invalid_input naming the file unless it is a 16-bit PNG with 3 channels.
FlowField read_kitti_flow_png(const std::filesystem::path& path);
// Each component rounded to the nearest 1/64 px and clamped to the format's range
// [−512, 512 − 1/64]; unknown flow is written as invalid (blue 0, red and green 0). Atomic, like
// write_flo().
void write_kitti_flow_png(const std::filesystem::path& path, const FlowField& flow);
// The KITTI quantisation of one component, as write_kitti_flow_png stores it: round(64·c) + 2^15,
// clamped to 0..65535.
std::uint16_t kitti_flow_value(float component);

// A flow file by its content: Middlebury .flo (magic "PIEH") or a KITTI flow PNG. Anything else
// is invalid_input naming the file and both formats.
FlowField read_flow_file(const std::filesystem::path& path);

// An 8-bit colour image, interleaved R, G, B, row-major.
struct ColorImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // 3·width·height bytes

  const std::uint8_t* pixel(int x, int y) const {
    return rgb.data() + 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x));
  }
};

// The largest |(u, v)| over the known vectors; 0 when there is none.
float max_flow_magnitude(const FlowField& flow);

// Middlebury colour coding. `max_magnitude` is the normalising radius in pixels; 0 takes the
// field's own maximum (1 if the field is all zero or unknown). Pass a fixed radius to colour a
// sequence of fields on one scale. Throws invalid_input for a negative or non-finite radius.
ColorImage flow_to_color(const FlowField& flow, float max_magnitude = 0);

// The legend of flow_to_color(): a colour wheel `size` pixels across on a white square, i.e. the
// colour of every flow vector up to the normalising radius (the wheel's rim), +u to the right
// and +v down as in the image. Throws invalid_input unless size >= 8.
ColorImage color_wheel_legend(int size);

// Copies `legend` into the bottom-right corner of `image`, inside a margin of `margin` pixels
// (shrinking nothing: a legend larger than the image is clipped).
void paste_legend(ColorImage& image, const ColorImage& legend, int margin = 4);

// An 8-bit colour image saved as a PNG (whatever the extension), through a temporary file and
// rename.
void write_color_png(const std::filesystem::path& path, const ColorImage& image);

// flow_to_color() saved as a PNG, as write_color_png().
void write_flow_png(const std::filesystem::path& path, const FlowField& flow, float max_magnitude = 0);

}  // namespace inertialnet
