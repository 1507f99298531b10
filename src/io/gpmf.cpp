// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/io/gpmf.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/excerpt.hpp"
#include "io/input_file.hpp"

namespace fs = std::filesystem;

namespace inertialnet {

namespace {

constexpr double kGyroLimit = 1e3;             // rad/s, as the CSV readers (gyro_log.cpp)
constexpr std::uint64_t kMaxMoov = 256u << 20;  // a moov beyond this is not a camera's (hours of video take a few MB)
constexpr std::uint64_t kMaxPayload = 64u << 20;  // GoPro writes a payload a second, a few kB
constexpr int kMaxDepth = 8;                    // GPMF nests DEVC → STRM; deeper is damage, not data

std::uint16_t be16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] << 8 | p[1]); }
std::uint32_t be32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}
std::uint64_t be64(const std::uint8_t* p) { return std::uint64_t(be32(p)) << 32 | be32(p + 4); }

// A FourCC as text, unprintable bytes as '?', for messages.
std::string fourcc(const std::uint8_t* p) {
  std::string s(reinterpret_cast<const char*>(p), 4);
  for (char& c : s) c = std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return s;
}

struct Box {
  std::string type;
  std::uint64_t offset = 0;  // of the header, in the file
  std::size_t begin = 0;     // the payload, as indices into the buffer holding it
  std::size_t end = 0;
};

class Mp4File {
 public:
  explicit Mp4File(const fs::path& file) : file_(file), in_(io_detail::open_input_file(file, "The IMU file")) {
    std::error_code ec;
    size_ = fs::file_size(file, ec);
    if (ec) throw invalid_input("The IMU file " + io_detail::quoted(file) + " cannot be sized: " + ec.message() + ".");
  }

  [[noreturn]] void damaged(std::uint64_t offset, const std::string& what) const {
    throw invalid_input(file_.string() + ": damaged MP4 at byte offset " + std::to_string(offset) + ": " + what + ".");
  }

  std::uint64_t size() const { return size_; }
  const fs::path& path() const { return file_; }

  std::vector<std::uint8_t> read(std::uint64_t offset, std::uint64_t n) {
    if (offset > size_ || n > size_ - offset) damaged(offset, std::to_string(n) + " bytes run past the file's end");
    std::vector<std::uint8_t> out(static_cast<std::size_t>(n));
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
    in_.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(n));
    if (in_.gcount() != static_cast<std::streamsize>(n)) {
      throw runtime_error(file_.string() + ": reading " + std::to_string(n) + " bytes at offset " +
                          std::to_string(offset) + " failed.");
    }
    return out;
  }

  // The top-level boxes, read header by header (the media data may be gigabytes).
  std::vector<Box> top_level() {
    std::vector<Box> boxes;
    std::uint64_t at = 0;
    while (at < size_) {
      if (size_ - at < 8) damaged(at, "a box header is cut short (" + std::to_string(size_ - at) + " bytes left)");
      const auto head = read(at, std::min<std::uint64_t>(16, size_ - at));
      std::uint64_t length = be32(head.data()), header = 8;
      if (length == 1) {
        if (head.size() < 16) damaged(at, "a 64-bit box size is cut short");
        length = be64(head.data() + 8);
        header = 16;
      } else if (length == 0) {
        length = size_ - at;  // "to the end of the file"
      }
      if (length < header || length > size_ - at) {
        damaged(at, "box '" + fourcc(head.data() + 4) + "' claims " + std::to_string(length) +
                        " bytes, beyond the file's end (" + std::to_string(size_) + " bytes)");
      }
      boxes.push_back({fourcc(head.data() + 4), at, static_cast<std::size_t>(header), static_cast<std::size_t>(length)});
      at += length;
    }
    return boxes;
  }

 private:
  fs::path file_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

// The boxes inside [begin, end) of `buf`, whose first byte is at file offset `base`.
std::vector<Box> children(const Mp4File& mp4, const std::vector<std::uint8_t>& buf, std::uint64_t base,
                          std::size_t begin, std::size_t end) {
  std::vector<Box> boxes;
  std::size_t at = begin;
  while (at < end) {
    if (end - at < 8) mp4.damaged(base + at, "a box header is cut short inside its parent");
    std::uint64_t length = be32(&buf[at]), header = 8;
    if (length == 1) {
      if (end - at < 16) mp4.damaged(base + at, "a 64-bit box size is cut short");
      length = be64(&buf[at + 8]);
      header = 16;
    } else if (length == 0) {
      length = end - at;
    }
    if (length < header || length > end - at) {
      mp4.damaged(base + at, "box '" + fourcc(&buf[at + 4]) + "' claims " + std::to_string(length) +
                                 " bytes, beyond its parent (" + std::to_string(end - at) + " left)");
    }
    boxes.push_back({fourcc(&buf[at + 4]), base + at, at + static_cast<std::size_t>(header),
                     at + static_cast<std::size_t>(length)});
    at += static_cast<std::size_t>(length);
  }
  return boxes;
}

std::optional<Box> child(const Mp4File& mp4, const std::vector<std::uint8_t>& buf, std::uint64_t base, const Box& parent,
                         const char* type) {
  for (const Box& b : children(mp4, buf, base, parent.begin, parent.end)) {
    if (b.type == type) return b;
  }
  return std::nullopt;
}

// One track's sample table: where each sample lies and when it starts.
struct Track {
  std::string handler, format;
  std::uint32_t timescale = 0;
  std::vector<std::uint64_t> offset, size, start, duration;  // start and duration in timescale units
};

// A full box's payload must hold `n` bytes.
void need(const Mp4File& mp4, const Box& box, std::size_t n) {
  if (box.end - box.begin < n) {
    mp4.damaged(box.offset, "box '" + box.type + "' holds " + std::to_string(box.end - box.begin) +
                                " bytes, fewer than the " + std::to_string(n) + " its entries need");
  }
}

Track read_track(Mp4File& mp4, const std::vector<std::uint8_t>& buf, std::uint64_t base, const Box& trak,
                 bool with_samples) {
  Track track;
  const auto required = [&](const Box& parent, const char* type) {
    const auto b = child(mp4, buf, base, parent, type);
    if (!b) mp4.damaged(parent.offset, "box '" + parent.type + "' has no '" + type + "' box");
    return *b;
  };
  const Box mdia = required(trak, "mdia");
  const Box hdlr = required(mdia, "hdlr");
  need(mp4, hdlr, 12);
  track.handler = fourcc(&buf[hdlr.begin + 8]);
  const Box mdhd = required(mdia, "mdhd");
  need(mp4, mdhd, 4);
  const bool v1 = buf[mdhd.begin] == 1;
  need(mp4, mdhd, v1 ? 24 : 16);
  track.timescale = be32(&buf[mdhd.begin + (v1 ? 20 : 12)]);
  const Box stbl = required(required(mdia, "minf"), "stbl");
  const Box stsd = required(stbl, "stsd");
  need(mp4, stsd, 16);
  track.format = fourcc(&buf[stsd.begin + 12]);
  if (!with_samples) return track;
  if (track.timescale == 0) mp4.damaged(mdhd.offset, "the track's timescale is 0");

  const Box stsz = required(stbl, "stsz");
  need(mp4, stsz, 12);
  const std::uint32_t uniform = be32(&buf[stsz.begin + 4]), count = be32(&buf[stsz.begin + 8]);
  if (uniform == 0) need(mp4, stsz, 12 + 4 * std::size_t(count));
  if (uniform != 0 && std::uint64_t(uniform) * count > mp4.size()) {
    mp4.damaged(stsz.offset, std::to_string(count) + " samples of " + std::to_string(uniform) + " bytes exceed the file");
  }
  for (std::uint32_t k = 0; k < count; ++k) track.size.push_back(uniform ? uniform : be32(&buf[stsz.begin + 12 + 4 * k]));

  const Box stts = required(stbl, "stts");
  need(mp4, stts, 8);
  const std::uint32_t entries = be32(&buf[stts.begin + 4]);
  need(mp4, stts, 8 + 8 * std::size_t(entries));
  std::uint64_t t = 0;
  for (std::uint32_t e = 0; e < entries; ++e) {
    const std::uint32_t n = be32(&buf[stts.begin + 8 + 8 * e]), delta = be32(&buf[stts.begin + 12 + 8 * e]);
    if (n > count - track.start.size()) {
      mp4.damaged(stts.offset, "its durations cover more samples than the " + std::to_string(count) + " stsz lists");
    }
    for (std::uint32_t k = 0; k < n; ++k, t += delta) {
      track.start.push_back(t);
      track.duration.push_back(delta);
    }
  }
  if (track.start.size() != count) {
    mp4.damaged(stts.offset, "its durations cover " + std::to_string(track.start.size()) + " samples, stsz lists " +
                                 std::to_string(count));
  }

  std::vector<std::uint64_t> chunks;
  if (const auto stco = child(mp4, buf, base, stbl, "stco")) {
    need(mp4, *stco, 8);
    const std::uint32_t n = be32(&buf[stco->begin + 4]);
    need(mp4, *stco, 8 + 4 * std::size_t(n));
    for (std::uint32_t k = 0; k < n; ++k) chunks.push_back(be32(&buf[stco->begin + 8 + 4 * k]));
  } else {
    const Box co64 = required(stbl, "co64");
    need(mp4, co64, 8);
    const std::uint32_t n = be32(&buf[co64.begin + 4]);
    need(mp4, co64, 8 + 8 * std::size_t(n));
    for (std::uint32_t k = 0; k < n; ++k) chunks.push_back(be64(&buf[co64.begin + 8 + 8 * k]));
  }
  const Box stsc = required(stbl, "stsc");
  need(mp4, stsc, 8);
  const std::uint32_t runs = be32(&buf[stsc.begin + 4]);
  need(mp4, stsc, 8 + 12 * std::size_t(runs));
  std::size_t run = 0, sample = 0;
  for (std::size_t c = 0; c < chunks.size() && sample < count; ++c) {
    // The last run whose first chunk (1-based) is at or before this one gives its sample count.
    while (run + 1 < runs && be32(&buf[stsc.begin + 8 + 12 * (run + 1)]) <= c + 1) ++run;
    if (runs == 0 || be32(&buf[stsc.begin + 8 + 12 * run]) > c + 1) {
      mp4.damaged(stsc.offset, "no sample-to-chunk entry covers chunk " + std::to_string(c + 1));
    }
    std::uint64_t at = chunks[c];
    const std::uint32_t per_chunk = be32(&buf[stsc.begin + 12 + 12 * run]);
    for (std::uint32_t k = 0; k < per_chunk && sample < count; ++k, ++sample) {
      if (at > mp4.size() || track.size[sample] > mp4.size() - at) {
        mp4.damaged(at, "sample " + std::to_string(sample) + " of the '" + track.format + "' track (" +
                            std::to_string(track.size[sample]) + " bytes) runs past the file's end (" +
                            std::to_string(mp4.size()) + " bytes)");
      }
      track.offset.push_back(at);
      at += track.size[sample];
    }
  }
  if (sample != count) {
    mp4.damaged(stsc.offset, "its chunks place " + std::to_string(sample) + " of the " + std::to_string(count) +
                                 " samples that stsz lists");
  }
  return track;
}

// GPMF's numeric types (gpmf-parser README, "Type"): the size of one value, and the value.
std::size_t type_size(char type) {
  switch (type) {
    case 'b': case 'B': return 1;
    case 's': case 'S': return 2;
    case 'l': case 'L': case 'f': return 4;
    case 'd': case 'j': case 'J': return 8;
    default: return 0;
  }
}

double number(char type, const std::uint8_t* p) {
  switch (type) {
    case 'b': return static_cast<std::int8_t>(p[0]);
    case 'B': return p[0];
    case 's': return static_cast<std::int16_t>(be16(p));
    case 'S': return be16(p);
    case 'l': return static_cast<std::int32_t>(be32(p));
    case 'L': return be32(p);
    case 'f': {
      const std::uint32_t bits = be32(p);
      float f;
      std::memcpy(&f, &bits, 4);
      return f;
    }
    case 'd': {
      const std::uint64_t bits = be64(p);
      double d;
      std::memcpy(&d, &bits, 8);
      return d;
    }
    case 'j': return static_cast<double>(static_cast<std::int64_t>(be64(p)));
    case 'J': return static_cast<double>(be64(p));
    default: return 0;
  }
}

struct Stream {
  std::vector<double> scale;  // SCAL: one divisor, or one per axis
  std::string orientation;    // ORIN
};

struct Payload {
  std::vector<std::array<double, 3>> gyro;
  std::string orientation;  // the ORIN of the stream that held GYRO
  std::vector<std::string> streams;  // FourCCs of the data met, for the message when GYRO is missing
};

class GpmfReader {
 public:
  GpmfReader(const Mp4File& mp4, const std::vector<std::uint8_t>& buf, std::uint64_t base)
      : mp4_(mp4), buf_(buf), base_(base) {}

  [[noreturn]] void damaged(std::size_t at, const std::string& what) const {
    throw invalid_input(mp4_.path().string() + ": damaged GPMF at byte offset " + std::to_string(base_ + at) + ": " +
                        what + ".");
  }

  void parse(std::size_t begin, std::size_t end, int depth, Stream* stream, Payload& out) const {
    if (depth > kMaxDepth) damaged(begin, "nested deeper than " + std::to_string(kMaxDepth) + " levels");
    std::size_t at = begin;
    while (end - at >= 8) {
      const std::uint8_t* p = &buf_[at];
      const std::string key = fourcc(p);
      const char type = static_cast<char>(p[4]);
      const std::size_t struct_size = p[5], repeat = be16(p + 6), length = struct_size * repeat;
      if (length > end - at - 8) {
        damaged(at, key + " claims " + std::to_string(length) + " bytes, " + std::to_string(end - at - 8) +
                        " are left in its container");
      }
      const std::size_t data = at + 8;
      if (type == 0) {
        if (key == "STRM") {
          Stream s;
          parse(data, data + length, depth + 1, &s, out);
        } else {
          parse(data, data + length, depth + 1, nullptr, out);
        }
      } else if (stream && key == "SCAL") {
        const std::size_t size = type_size(type);
        if (size == 0) damaged(at, std::string("SCAL has the non-numeric type '") + type + "'");
        stream->scale.clear();
        for (std::size_t k = 0; k + size <= length; k += size) {
          const double v = number(type, &buf_[data + k]);
          if (!std::isfinite(v) || v == 0) damaged(data + k, "a SCAL divisor is " + std::to_string(v));
          stream->scale.push_back(v);
        }
      } else if (stream && key == "ORIN" && type == 'c') {
        stream->orientation.assign(reinterpret_cast<const char*>(&buf_[data]), length);
      } else if (key == "GYRO") {
        read_gyro(at, type, struct_size, repeat, stream, out);
      } else if (stream && std::isupper(static_cast<unsigned char>(key[0])) && key != "STNM" && key != "SIUN" &&
                 key != "UNIT" && key != "TSMP" && key != "STMP" && key != "TYPE") {
        out.streams.push_back(key);
      }
      at = data + ((length + 3) & ~std::size_t(3));
      if (at > end) break;  // the last item's padding may be cut by its container
    }
  }

 private:
  void read_gyro(std::size_t at, char type, std::size_t struct_size, std::size_t repeat, const Stream* stream,
                 Payload& out) const {
    const std::size_t size = type_size(type);
    if (size == 0 || struct_size != 3 * size) {
      damaged(at, "GYRO has type '" + std::string(1, type) + "' and " + std::to_string(struct_size) +
                      "-byte samples; a gyro sample is three numbers (int16 as GoPro writes them)");
    }
    std::vector<double> scale = stream && !stream->scale.empty() ? stream->scale : std::vector<double>{1.0};
    if (scale.size() != 1 && scale.size() != 3) {
      damaged(at, "the GYRO stream's SCAL has " + std::to_string(scale.size()) + " divisors, expected 1 or 3");
    }
    if (stream) out.orientation = stream->orientation;
    for (std::size_t n = 0; n < repeat; ++n) {
      std::array<double, 3> v{};
      for (std::size_t c = 0; c < 3; ++c) {
        const std::size_t where = at + 8 + n * struct_size + c * size;
        v[c] = number(type, &buf_[where]) / scale[scale.size() == 1 ? 0 : c];
        if (!(std::fabs(v[c]) <= kGyroLimit)) {
          std::ostringstream s;
          s << "a GYRO value is " << v[c] << " rad/s (after SCAL), beyond ±1000 rad/s";
          damaged(where, s.str());
        }
      }
      out.gyro.push_back(v);
    }
  }

  const Mp4File& mp4_;
  const std::vector<std::uint8_t>& buf_;
  std::uint64_t base_;
};

// The stored channel order: ORIN when it is three distinct letters of X, Y, Z (lower case:
// negated), else HERO5's Z,X,Y. Returns, per channel, the labelled axis and its sign.
struct AxisOrder {
  std::array<int, 3> axis{2, 0, 1};
  std::array<double, 3> sign{1, 1, 1};
  std::string text = "ZXY";
};

std::optional<AxisOrder> parse_orin(const std::string& text) {
  if (text.size() < 3) return std::nullopt;
  AxisOrder order;
  order.text = text.substr(0, 3);
  bool seen[3] = {false, false, false};
  for (int c = 0; c < 3; ++c) {
    const char ch = text[c];
    const int a = std::toupper(static_cast<unsigned char>(ch)) - 'X';
    if (a < 0 || a > 2 || seen[a]) return std::nullopt;
    seen[a] = true;
    order.axis[c] = a;
    order.sign[c] = std::isupper(static_cast<unsigned char>(ch)) ? 1.0 : -1.0;
  }
  return order;
}

}  // namespace

bool is_mp4(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char head[8] = {};
  if (!in.read(head, 8)) return false;
  return std::memcmp(head + 4, "ftyp", 4) == 0;
}

GyroLog read_gpmf_gyro(const fs::path& file) {
  Mp4File mp4(file);
  std::optional<Box> moov;
  for (const Box& b : mp4.top_level()) {
    if (b.type == "moov") moov = b;
  }
  if (!moov) throw invalid_input(file.string() + " is an MP4 without a 'moov' box: it has no tracks to read a gyro from.");
  const std::uint64_t moov_size = moov->end - moov->begin;
  if (moov_size > kMaxMoov) {
    mp4.damaged(moov->offset, "its 'moov' box claims " + std::to_string(moov_size) + " bytes, more than a camera writes");
  }
  const std::uint64_t base = moov->offset + moov->begin;
  const std::vector<std::uint8_t> buf = mp4.read(base, moov_size);
  Box root{"moov", moov->offset, 0, buf.size()};

  std::optional<Track> gpmd;
  std::string found;
  for (const Box& trak : children(mp4, buf, base, root.begin, root.end)) {
    if (trak.type != "trak") continue;
    const Track head = read_track(mp4, buf, base, trak, false);
    found += (found.empty() ? "" : ", ") + head.handler + "/" + head.format;
    if (head.format == "gpmd" && !gpmd) gpmd = read_track(mp4, buf, base, trak, true);
  }
  if (!gpmd) {
    throw invalid_input(file.string() + " is an MP4 without GoPro metadata (a track whose sample description is "
                        "'gpmd'; tracks found, handler/format: " + (found.empty() ? "none" : found) +
                        "): it holds no gyro that inertialnet reads. Give the gyro log with --imu FILE.");
  }

  // Every payload's gyro, and where its samples start in the stream's count.
  std::vector<std::array<double, 3>> gyro;
  std::vector<double> payload_start, payload_count;
  std::string orientation, streams;
  for (std::size_t k = 0; k < gpmd->offset.size(); ++k) {
    if (gpmd->size[k] > kMaxPayload) {
      mp4.damaged(gpmd->offset[k], "GPMF payload " + std::to_string(k) + " claims " + std::to_string(gpmd->size[k]) +
                                       " bytes, more than a camera writes");
    }
    const auto payload = mp4.read(gpmd->offset[k], gpmd->size[k]);
    Payload out;
    GpmfReader(mp4, payload, gpmd->offset[k]).parse(0, payload.size(), 0, nullptr, out);
    payload_start.push_back(static_cast<double>(gpmd->start[k]) / gpmd->timescale);
    payload_count.push_back(static_cast<double>(gyro.size()));
    gyro.insert(gyro.end(), out.gyro.begin(), out.gyro.end());
    if (!out.orientation.empty()) orientation = out.orientation;
    for (const auto& s : out.streams) {
      if (streams.find(s) == std::string::npos && streams.size() < 200) streams += (streams.empty() ? "" : ", ") + s;
    }
  }
  if (gyro.empty()) {
    throw invalid_input(file.string() + "'s GoPro metadata (GPMF) has no GYRO samples (data found: " +
                        (streams.empty() ? "none" : streams) + ").");
  }

  // t(n) = t0 + n·dt, fitted to (running count, payload start) as gpmf-parser's README advises:
  // the payload times come from the MP4 clock, the sample count from the sensor.
  const std::size_t m = payload_start.size();
  double t0 = 0, dt = 0;
  double mean_n = 0, mean_t = 0;
  for (std::size_t k = 0; k < m; ++k) {
    mean_n += payload_count[k] / m;
    mean_t += payload_start[k] / m;
  }
  double snn = 0, snt = 0;
  for (std::size_t k = 0; k < m; ++k) {
    snn += (payload_count[k] - mean_n) * (payload_count[k] - mean_n);
    snt += (payload_count[k] - mean_n) * (payload_start[k] - mean_t);
  }
  if (snn > 0) {
    dt = snt / snn;
    t0 = mean_t - dt * mean_n;
  } else {
    // One payload (or all gyro in the first): spread its samples over its duration.
    dt = static_cast<double>(gpmd->duration.front()) / gpmd->timescale / static_cast<double>(gyro.size());
    t0 = payload_start.front();
  }
  if (!(dt > 0) || !std::isfinite(dt) || !std::isfinite(t0)) {
    throw invalid_input(file.string() + ": the GPMF payload times do not advance with the gyro sample count, so "
                        "its " + std::to_string(gyro.size()) + " gyro samples cannot be timed.");
  }

  AxisOrder order;
  const auto orin = parse_orin(orientation);
  GyroLog log;
  const std::string name = file.filename().string();
  if (orin) {
    order = *orin;
  } else {
    log.notes.push_back(name + ": " + (orientation.empty() ? "no ORIN in its GPMF" : "its ORIN \"" + excerpt(orientation) + "\" is not three axis letters") +
                        ", so the gyro axes are taken in HERO5 Black/Session's order Z,X,Y (HERO6 stores Y,-X,Z "
                        "and Fusion -Y,X,Z: give --T-cam-imu for those cameras).");
  }
  for (std::size_t n = 0; n < gyro.size(); ++n) {
    ImuSample s;
    s.t_ns = std::llround((t0 + dt * static_cast<double>(n)) * 1e9);
    for (int c = 0; c < 3; ++c) s.gyro[order.axis[c]] = order.sign[c] * gyro[n][c];
    log.samples.push_back(s);
  }
  std::ostringstream rate;
  rate.precision(6);
  rate << 1.0 / dt;
  log.notes.push_back(name + ": " + std::to_string(gyro.size()) + " gyro samples from its GoPro metadata (GPMF, axis "
                      "order " + order.text + "), timed by a fit to the payload times: " + rate.str() +
                      " Hz from t = " + std::to_string(log.samples.front().t_ns) + " ns on the video's clock.");
  log.imu_to_camera = Mat3{-1, 0, 0, 0, 0, -1, 0, -1, 0};
  log.imu_to_camera_source = "GoPro's IMU axis labels (X left, Y back, Z up seen from the rear screen: camera "
                             "x = -X, y = -Z, z = -Y); --T-cam-imu or --camchain replaces it";
  return log;
}

}  // namespace inertialnet
