// SPDX-License-Identifier: Apache-2.0
// What the InertialNet head sees: the flow of a frame pair turned into the head's input, the one
// function `train` (train/training_set.hpp) and `predict` (pipeline/rates_processor.hpp) both call,
// so that a head runs on any frame size exactly as it was trained.
//
// Two conventions, recorded in a trained head's metadata ("inertialnet.head_input"):
// - paper: the flow in pixels, resized to the head's size with its vectors scaled by the size
//   ratio (the paper's input: a head sees one camera at one frame rate);
// - normalized: that resized flow divided by the frame interval and by the focal lengths at the
//   head's size, i.e. u/(fx·dt), v/(fy·dt): image velocity in normalised camera coordinates per
//   second. A pure rotation ω gives ≈ (−ωy, ωx) at the image centre whatever the camera's focal
//   length, resolution or frame rate, so a head trained on one camera and rate sees another's
//   motion on the same scale, and a 430 ms gap is no longer a 13× larger input than a 33 ms pair.
// A head without the metadata (converted from the paper's checkpoints, trained before it existed)
// is a paper head.
#pragma once

#include <string>
#include <vector>

namespace inertialnet {

class SafetensorsFile;

enum class HeadInput { Paper, Normalized };
std::string to_string(HeadInput input);              // "paper", "normalized"
HeadInput parse_head_input(const std::string& text);  // invalid_input listing the choices

// Metadata key of a trained head: head_input_to_json().
inline constexpr const char* kMetadataHeadInput = "inertialnet.head_input";

// How a head was trained: its input convention, the flow method it learned from ("dis",
// "dis-fine", "flownet2"; empty when unknown: each is another flow, pipeline/rates_processor.hpp),
// and the frame of the rates it answers in. A head trained on body-frame (gyro) targets has
// learned its training rig's camera-to-IMU rotation with the motion: on another rig its rates
// come out in the wrong frame. A normalized head is therefore trained on
// camera-frame targets and `predict` turns its answer into the body frame with the sequence's own
// rotation; paper heads (and normalized heads written before, without "frame") answer in the body
// frame of the rig they were trained on.
struct HeadInputInfo {
  HeadInput convention = HeadInput::Paper;
  std::string flow;
  bool camera_frame = false;
};

// {"convention":"normalized","flow":"dis","frame":"camera"} (keys sorted, compact; "frame" is
// "camera" or "body", and read as "body" when absent).
std::string head_input_to_json(const HeadInputInfo& info);
// invalid_input for anything else than the object above (an unknown convention, a wrong type).
HeadInputInfo head_input_from_json(const std::string& json);
// The head-input metadata of the first of `paths` that has it (the paper's, flow unknown, when
// none does); a malformed one is invalid_input naming the file and the key. Reads the headers only.
HeadInputInfo read_head_input(const std::vector<std::string>& paths);
// The same from files already open (io/safetensors.hpp), their headers read once.
HeadInputInfo read_head_input(const std::vector<SafetensorsFile>& files);

// A planar [2, h, w] flow in pixels resized to out_w × out_h: area averaging when shrinking (no
// aliasing of fine flow detail), bilinear otherwise, u and v scaled by the size ratio.
std::vector<float> resize_flow(const float* flow, int w, int h, int out_w, int out_h);

// The head's input [2, out_h, out_w] from a planar pixel flow [2, h, w] of frames `dt_s` seconds
// apart, taken by a camera of focal lengths fx, fy (pixels, at w × h): resize_flow(), then for
// the normalized convention each plane divided by its focal length at the head's size times dt.
// The paper convention ignores dt_s, fx and fy. invalid_input for a non-positive or non-finite
// dt or focal length with the normalized convention.
std::vector<float> head_input(const float* flow, int w, int h, int out_w, int out_h, HeadInput convention,
                              double dt_s, double fx, double fy);

}  // namespace inertialnet
