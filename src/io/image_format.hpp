// SPDX-License-Identifier: Apache-2.0
// Internal to io: which frame format an encoded image is, from its first bytes. Not public API.
//
// Why it exists: cv::imdecode picks a decoder by signature among every codec OpenCV was built
// with, and Debian's OpenCV has more than the frame formats we document — among them DICOM
// through GDCM, which abort()s the whole process (an assert) on a damaged file that merely has
// "DICM" at byte 128. So only bytes that are one of our formats reach OpenCV, and each test below
// implies the signature test of OpenCV's decoder for that format, so OpenCV picks that decoder.
#pragma once

#include <string>
#include <vector>

namespace inertialnet::io_detail {

enum class ImageFormat { Unknown, Png, Jpeg, Bmp, Tiff, Pnm, WebP };

ImageFormat image_format_of(const std::vector<unsigned char>& bytes);

inline bool is_png(const std::vector<unsigned char>& bytes) { return image_format_of(bytes) == ImageFormat::Png; }

// For a message about bytes of no format we read: what they look like when that is a format
// people use ("a DICOM file", "an OpenEXR file", …), else empty.
std::string foreign_image_format(const std::vector<unsigned char>& bytes);

// "PNG, JPEG, BMP, TIFF, PNM (.pgm/.ppm/.pnm) or WebP": the list every refusal names.
extern const char* const kReadableImageFormats;

}  // namespace inertialnet::io_detail
