// SPDX-License-Identifier: Apache-2.0
// The gyro a GoPro embeds in its MP4 (GPMF, github.com/gopro/gpmf-parser), read for `--imu rec.mp4`.
//
// The MP4 (ISO base media) boxes are walked to the track whose sample description is `gpmd`
// (GoPro's `meta` track); its samples (payloads) are found through stts/stsz/stsc/stco|co64, as
// every MP4 track's are. Each payload is GPMF: KLV items of a FourCC, a type byte, a structure size
// byte and a 16-bit big-endian repeat, the data padded to 4 bytes; type 0 nests (DEVC → STRM).
// In a STRM, GYRO holds int16 triples (or another numeric type) divided by the stream's SCAL
// (one divisor, or one per axis) into rad/s.
//
// Times: GPMF stores none per sample. As gpmf-parser's README advises, the n-th sample of the
// stream is placed at t0 + n·dt, t0 and dt fitted (least squares) to the payloads' start times on
// the MP4 clock (stts) against the running sample count; nanoseconds from the MP4 timeline's
// origin, which is where the video's frame times start (video_file.cpp), so `eval rec.mp4 --imu
// rec.mp4` pairs them. Edit lists are not applied (GoPro writes none that shift a track).
//
// Axes: a stored triple is in the order an `ORIN` string in the stream gives (gpmf-parser's
// GPMF_common.h: "input channel data orientation, lowercase is negative, e.g. Zxy"), or, without one, HERO5 Black/Session's Z,X,Y (gpmf-parser
// README; HERO6 stores Y,-X,Z and Fusion -Y,X,Z without saying so: a note names the assumption).
// The samples are returned in GoPro's labelled frame (X, Y, Z of the README's "IMU Orientation Uses
// These Axis Labels"), and GyroLog::imu_to_camera is the rotation those labels give into our
// camera frame (x right, y down, z forward): x = -X, y = -Z, z = -Y. A calibration given
// (--T-cam-imu, --camchain) replaces that rotation and acts on the labelled X, Y, Z.
//
// Damaged input (a box or KLV item running past its container, a sample table that does not add
// up, a SCAL of zero, a gyro beyond ±1000 rad/s) is invalid_input naming the file and byte offset.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "inertialnet/io/gyro_log.hpp"

namespace inertialnet {

// True when `file` begins with an ISO base media `ftyp` box (MP4, MOV); false when it cannot be read.
bool is_mp4(const std::filesystem::path& file);

// The GYRO stream of the MP4's GPMF track, its notes, and GoPro's rotation into the camera frame.
GyroLog read_gpmf_gyro(const std::filesystem::path& file);

}  // namespace inertialnet
