// SPDX-License-Identifier: Apache-2.0
#include "io/image_format.hpp"

#include <cctype>
#include <cstddef>
#include <cstring>

namespace inertialnet::io_detail {

namespace {

bool starts_with(const std::vector<unsigned char>& bytes, std::size_t at, const char* text, std::size_t length) {
  return bytes.size() >= at + length && std::memcmp(bytes.data() + at, text, length) == 0;
}

bool has_dicom_magic(const std::vector<unsigned char>& bytes) { return starts_with(bytes, 128, "DICM", 4); }

}  // namespace

const char* const kReadableImageFormats = "PNG, JPEG, BMP, TIFF, PNM (.pgm/.ppm/.pnm) or WebP";

ImageFormat image_format_of(const std::vector<unsigned char>& bytes) {
  if (starts_with(bytes, 0, "\x89PNG\r\n\x1a\n", 8)) return ImageFormat::Png;
  if (starts_with(bytes, 0, "\xFF\xD8\xFF", 3)) return ImageFormat::Jpeg;
  if (starts_with(bytes, 0, "BM", 2)) return ImageFormat::Bmp;
  if (starts_with(bytes, 0, "II\x2A\0", 4) || starts_with(bytes, 0, "MM\0\x2A", 4)) return ImageFormat::Tiff;
  // P1…P6 then white space, exactly OpenCV's PxM test (P7 is PAM, Pf/PF are PFM: not frames).
  if (bytes.size() >= 3 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6' && std::isspace(bytes[2]) != 0) {
    return ImageFormat::Pnm;
  }
  // Two formats OpenCV may decline although their first bytes match: WebP (libwebp parses the
  // first 32 bytes and can refuse them) and BigTIFF (claimed only by newer OpenCVs). Declined,
  // the bytes fall through to the later decoders, DICOM's among them, so neither may carry
  // DICOM's magic.
  if (has_dicom_magic(bytes)) return ImageFormat::Unknown;
  if (starts_with(bytes, 0, "RIFF", 4) && starts_with(bytes, 8, "WEBP", 4)) return ImageFormat::WebP;
  if (starts_with(bytes, 0, "II\x2B\0", 4) || starts_with(bytes, 0, "MM\0\x2B", 4)) return ImageFormat::Tiff;
  return ImageFormat::Unknown;
}

std::string foreign_image_format(const std::vector<unsigned char>& bytes) {
  if (has_dicom_magic(bytes)) return "a DICOM file (\"DICM\" at byte 128)";
  if (starts_with(bytes, 0, "\x76\x2F\x31\x01", 4)) return "an OpenEXR file";
  if (starts_with(bytes, 0, "\0\0\0\x0CjP  ", 8) || starts_with(bytes, 0, "\xFF\x4F\xFF\x51", 4)) {
    return "a JPEG 2000 file";
  }
  if (starts_with(bytes, 0, "#?RADIANCE", 10) || starts_with(bytes, 0, "#?RGBE", 6)) return "a Radiance HDR file";
  if (starts_with(bytes, 0, "GIF8", 4)) return "a GIF file";
  if (starts_with(bytes, 0, "P7", 2)) return "a PAM file";
  if (starts_with(bytes, 0, "Pf", 2) || starts_with(bytes, 0, "PF", 2)) return "a PFM (float) file";
  if (starts_with(bytes, 0, "\x59\xA6\x6A\x95", 4)) return "a Sun raster file";
  return {};
}

}  // namespace inertialnet::io_detail
