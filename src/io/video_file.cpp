// SPDX-License-Identifier: Apache-2.0
#include "io/video_file.hpp"

#include <algorithm>
#include <map>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libswscale/swscale.h>
}

#include "inertialnet/runtime/error.hpp"
#include "io/input_file.hpp"
#include "io/third_party_log.hpp"

namespace inertialnet::io_detail {

namespace {

struct FormatCloser {
  void operator()(AVFormatContext* f) const { avformat_close_input(&f); }
};
struct CodecFreer {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct PacketFreer {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct FrameFreer {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct ScalerFreer {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};
using Format = std::unique_ptr<AVFormatContext, FormatCloser>;
using Packet = std::unique_ptr<AVPacket, PacketFreer>;
using Frame = std::unique_ptr<AVFrame, FrameFreer>;

std::string av_error_text(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

// Why FFmpeg refused: our words for the common cases, FFmpeg's own short error text otherwise.
std::string describe_open_error(int code) {
  if (code == AVERROR_INVALIDDATA) return "it is not in a container format FFmpeg reads";
  if (code == AVERROR(EACCES)) return "permission denied";
  if (code == AVERROR(ENOENT)) return "it does not exist";
  if (code == AVERROR(EISDIR)) return "it is a folder";
  return "FFmpeg says: " + av_error_text(code);
}

std::string describe_decode_error(int code, const char* codec) {
  if (code == AVERROR_INVALIDDATA) return std::string("its data is corrupt (FFmpeg's ") + codec + " decoder rejects it)";
  return std::string("FFmpeg's ") + codec + " decoder fails on it: " + av_error_text(code);
}

Packet new_packet() {
  Packet p(av_packet_alloc());
  if (!p) throw runtime_error("out of memory for an FFmpeg packet");
  return p;
}

// The container opened with its best video stream found; `stream` its index.
Format open_container(const std::filesystem::path& path, int& stream, const AVCodec*& codec) {
  AVFormatContext* raw = nullptr;
  const int opened = avformat_open_input(&raw, path.c_str(), nullptr, nullptr);
  if (opened < 0) throw invalid_input("cannot open " + quoted(path) + " as a video: " + describe_open_error(opened));
  Format format(raw);
  const int probed = avformat_find_stream_info(format.get(), nullptr);
  if (probed < 0) {
    throw invalid_input("cannot read the streams of the video " + quoted(path) + ": " + describe_open_error(probed));
  }
  codec = nullptr;
  stream = av_find_best_stream(format.get(), AVMEDIA_TYPE_VIDEO, -1, -1, &codec, 0);
  if (stream == AVERROR_STREAM_NOT_FOUND) throw invalid_input(quoted(path) + " holds no video stream");
  if (stream < 0 || !codec) {
    const AVCodecDescriptor* d = avcodec_descriptor_get(format->streams[std::max(stream, 0)]->codecpar->codec_id);
    throw invalid_input("the video " + quoted(path) + " is in a codec this FFmpeg cannot decode" +
                        (stream >= 0 && d ? std::string(" (") + d->name + ")" : std::string()));
  }
  return format;
}

// A packet's presentation time in stream units, or AV_NOPTS_VALUE.
std::int64_t packet_time(const AVPacket& p) { return p.pts != AV_NOPTS_VALUE ? p.pts : p.dts; }

}  // namespace

struct VideoFile::State {
  Format format;
  int stream = -1;
  const AVCodec* codec = nullptr;
  std::unique_ptr<AVCodecContext, CodecFreer> decoder;
  std::unique_ptr<SwsContext, ScalerFreer> scaler;
  Packet packet = new_packet();
  Frame picture{av_frame_alloc()};
  Frame bgr{av_frame_alloc()};
  std::vector<std::int64_t> keys;  // the frames' PTS in stream units, ascending; empty: by order
  bool picture_ready = false;      // `picture` holds a decoded frame not handed out yet
  bool input_ended = false;        // the decoder has been told the stream ended
  std::int64_t ordinal = 0;        // video packets read so far (the key when there are no PTS)
  std::int64_t last_sent = AV_NOPTS_VALUE;  // key of the packet the decoder got last
  std::map<std::int64_t, std::string> failed;  // key → why the decoder made no frame of it
  std::size_t failures_since_picture = 0;        // order-only streams: frames lost before `picture`
};

VideoFile::VideoFile(const std::filesystem::path& path) : path_(path), state_(std::make_unique<State>()) {
  // A FIFO or a device would block FFmpeg's open or read forever: regular, readable files only.
  open_input_file(path, "The video");
  route_third_party_logs();
  State& s = *state_;
  if (!s.picture || !s.bgr) throw runtime_error("out of memory for an FFmpeg frame");

  // The index: one pass over the packets, none decoded.
  {
    int stream = -1;
    const AVCodec* codec = nullptr;
    Format format = open_container(path, stream, codec);
    const AVStream* st = format->streams[stream];
    const AVRational rate = st->avg_frame_rate.num > 0 ? st->avg_frame_rate : st->r_frame_rate;
    if (rate.num > 0 && rate.den > 0) index_.nominal_fps = av_q2d(rate);
    bool timed = true;
    int read = 0;
    std::int64_t packets = 0;  // of the video stream, empty and discarded ones too: what the header counts
    while ((read = av_read_frame(format.get(), s.packet.get())) >= 0) {
      if (s.packet->stream_index == stream) ++packets;
      // An empty packet is no picture (AVI marks a frame the recorder dropped that way): the gap
      // shows in the times of its neighbours. A packet flagged for discarding (before an MP4 edit
      // list's start) is decoded as a reference only; the decoder gives no picture of it.
      if (s.packet->stream_index == stream && s.packet->size > 0 && !(s.packet->flags & AV_PKT_FLAG_DISCARD)) {
        ++index_.frames;
        const std::int64_t t = packet_time(*s.packet);
        if (t == AV_NOPTS_VALUE) timed = false;
        if (timed) s.keys.push_back(t);
      }
      av_packet_unref(s.packet.get());
    }
    // Only a video with fewer packets than its header announces is cut short (an announced count
    // of 0 is "unknown").
    if (st->nb_frames > packets) index_.announced = st->nb_frames;
    if (read != AVERROR_EOF) {
      index_.stopped = "reading it stopped at byte " + std::to_string(avio_tell(format->pb)) + " (" +
                       describe_open_error(read) + ")";
    }
    std::sort(s.keys.begin(), s.keys.end());
    if (!timed || std::adjacent_find(s.keys.begin(), s.keys.end()) != s.keys.end()) s.keys.clear();
    if (!s.keys.empty()) {
      const std::int64_t first = s.keys.front();
      const std::int64_t origin = st->start_time != AV_NOPTS_VALUE ? std::min(st->start_time, first) : first;
      for (const std::int64_t k : s.keys) {
        index_.times_ns.push_back(av_rescale_q(k - origin, st->time_base, AVRational{1, 1'000'000'000}));
      }
    }
  }

  // Reopened for decoding: seeking back in a damaged file is less sure than starting again.
  s.format = open_container(path, s.stream, s.codec);
  s.decoder.reset(avcodec_alloc_context3(s.codec));
  if (!s.decoder) throw runtime_error("out of memory for an FFmpeg decoder");
  const AVStream* st = s.format->streams[s.stream];
  if (avcodec_parameters_to_context(s.decoder.get(), st->codecpar) < 0) {
    throw invalid_input("the video stream of " + quoted(path) + " has codec parameters FFmpeg cannot use");
  }
  s.decoder->pkt_timebase = st->time_base;
  // A damaged frame is an error, not a picture with guessed-in blocks: its flow would be wrong.
  s.decoder->err_recognition |= AV_EF_EXPLODE;
  const int opened = avcodec_open2(s.decoder.get(), s.codec, nullptr);
  if (opened < 0) {
    throw invalid_input("cannot start FFmpeg's " + std::string(s.codec->name) + " decoder for " + quoted(path) + ": " +
                        av_error_text(opened));
  }
}

VideoFile::~VideoFile() = default;

std::optional<cv::Mat> VideoFile::frame(std::size_t i, std::string& why) {
  State& s = *state_;
  const bool by_time = !s.keys.empty();
  const std::int64_t wanted = by_time && i < s.keys.size() ? s.keys[i] : static_cast<std::int64_t>(i);
  auto note_failure = [&](std::int64_t key, std::string reason) {
    s.failed.emplace(key, std::move(reason));
    ++s.failures_since_picture;
  };
  auto failure_for = [&](std::int64_t key) {
    const auto found = s.failed.find(key);
    if (found != s.failed.end()) return found->second;
    if (s.failures_since_picture > 0) return std::string("its data is corrupt (the decoder made no picture of it)");
    return std::string("the decoder made no picture of it");
  };

  // Sends the next packet of the video stream (or the end of the stream) to the decoder.
  auto feed = [&] {
    for (;;) {
      const int read = av_read_frame(s.format.get(), s.packet.get());
      if (read < 0) {
        avcodec_send_packet(s.decoder.get(), nullptr);
        s.input_ended = true;
        return;
      }
      if (s.packet->stream_index != s.stream || s.packet->size <= 0) {
        av_packet_unref(s.packet.get());
        continue;
      }
      const std::int64_t key = by_time ? packet_time(*s.packet) : s.ordinal;
      ++s.ordinal;
      if (s.packet->flags & AV_PKT_FLAG_CORRUPT) {
        av_packet_unref(s.packet.get());
        note_failure(key, "the container marks its data as damaged or cut short");
        continue;
      }
      // Order-only streams: the key rides on the packet to the picture made of it.
      if (!by_time) s.packet->pts = key;
      const int sent = avcodec_send_packet(s.decoder.get(), s.packet.get());
      av_packet_unref(s.packet.get());
      if (sent < 0) {
        note_failure(key, describe_decode_error(sent, s.codec->name));
        continue;
      }
      s.last_sent = key;
      return;
    }
  };
  // Makes the next picture; false at the end of the stream.
  auto next_picture = [&] {
    for (;;) {
      const int got = avcodec_receive_frame(s.decoder.get(), s.picture.get());
      if (got == 0) {
        if (s.picture->decode_error_flags != 0 || (s.picture->flags & AV_FRAME_FLAG_CORRUPT)) {
          note_failure(s.picture->best_effort_timestamp, "its data is corrupt (the decoder could only guess parts of it)");
          av_frame_unref(s.picture.get());
          continue;
        }
        return true;
      }
      if (got == AVERROR_EOF) return false;
      if (got != AVERROR(EAGAIN)) {
        note_failure(s.last_sent, describe_decode_error(got, s.codec->name));
        continue;
      }
      if (s.input_ended) return false;
      feed();
    }
  };
  auto picture_key = [&] {
    const std::int64_t t = s.picture->best_effort_timestamp;
    return t != AV_NOPTS_VALUE ? t : s.picture->pts;
  };

  for (;;) {
    if (!s.picture_ready) {
      if (!next_picture()) {
        why = failure_for(wanted);
        if (s.failures_since_picture > 0) --s.failures_since_picture;
        return std::nullopt;
      }
      s.picture_ready = true;
    }
    if (by_time) {
      const std::int64_t key = picture_key();
      if (key != AV_NOPTS_VALUE && key < wanted) {  // a picture outside the index: not a frame of ours
        av_frame_unref(s.picture.get());
        s.picture_ready = false;
        continue;
      }
      if (key != AV_NOPTS_VALUE && key > wanted) {  // frame i was lost; the picture is a later frame's
        why = failure_for(wanted);
        return std::nullopt;
      }
    } else if (s.failures_since_picture > 0) {  // frames were lost before this picture, in order
      --s.failures_since_picture;
      why = failure_for(wanted);
      return std::nullopt;
    }
    s.failures_since_picture = 0;
    s.picture_ready = false;
    break;
  }

  // To BGR as OpenCV's VideoCapture does (cap_ffmpeg_impl.hpp, 4.6): the coded size, bicubic
  // swscale, a 32-byte aligned buffer; then the picture's own size is cut out.
  AVFrame& p = *s.picture;
  const int width = std::max(s.decoder->coded_width, p.width), height = std::max(s.decoder->coded_height, p.height);
  s.scaler.reset(sws_getCachedContext(s.scaler.release(), width, height, static_cast<AVPixelFormat>(p.format), width,
                                      height, AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr, nullptr));
  if (!s.scaler) {
    av_frame_unref(&p);
    why = "FFmpeg cannot convert its pixel format to BGR";
    return std::nullopt;
  }
  AVFrame& out = *s.bgr;
  if (out.width != width || out.height != height || !out.data[0]) {
    av_frame_unref(&out);
    out.format = AV_PIX_FMT_BGR24;
    out.width = width;
    out.height = height;
    if (av_frame_get_buffer(&out, 32) < 0) throw runtime_error("out of memory for a " + std::to_string(width) + " × " +
                                                                std::to_string(height) + " video frame");
  }
  sws_scale(s.scaler.get(), p.data, p.linesize, 0, height, out.data, out.linesize);
  const cv::Mat whole(height, width, CV_8UC3, out.data[0], static_cast<std::size_t>(out.linesize[0]));
  cv::Mat result = whole(cv::Rect(0, 0, p.width, p.height)).clone();
  av_frame_unref(&p);
  return result;
}

}  // namespace inertialnet::io_detail
