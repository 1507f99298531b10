// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/ops/gemm/gemm.hpp"

#include <clblast.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <set>
#include <string>
#include <unordered_map>

#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/runtime/device.hpp"
#include "ops/gemm/operand_check.hpp"
#include "runtime/clblast_tuning.hpp"

namespace inertialnet {

namespace detail {

void check_gemm_operand(const char* name, const MatrixView& view, std::size_t rows, std::size_t cols,
                        std::size_t stride, std::size_t batch) {
  if (!view.buffer) throw invalid_input(std::string("GEMM operand ") + name + " has no buffer");
  if (view.leading_dimension < cols) {
    throw invalid_input(std::string("GEMM operand ") + name + ": leading dimension " +
                        std::to_string(view.leading_dimension) + " is smaller than its " + std::to_string(cols) +
                        " columns");
  }
  const std::size_t extent = (rows - 1) * view.leading_dimension + cols;
  const std::size_t last = view.offset + (batch - 1) * stride + extent;
  if (last > view.buffer_floats) {
    throw invalid_input(std::string("GEMM operand ") + name + " (" + std::to_string(rows) + "×" + std::to_string(cols) +
                        ", ld " + std::to_string(view.leading_dimension) + ", offset " + std::to_string(view.offset) +
                        (batch > 1 ? ", " + std::to_string(batch) + " batches" : std::string()) + ") needs " +
                        std::to_string(last) + " floats, its buffer holds " + std::to_string(view.buffer_floats));
  }
}

}  // namespace detail

namespace {

// CLBlast keeps process-wide caches of compiled programs and tuning data, and calling it from
// several threads at once (the pipeline's lanes) crashed intermittently here, as reported
// upstream for multi-threaded use (CLBlast issue 486). Calls only enqueue work — the GEMM runs
// after the lock is released — so serialising them costs the lanes no overlap.
std::mutex& clblast_mutex() {
  static std::mutex mutex;
  return mutex;
}

// Drops the Xgemm parameters the device's tuning file set (the set in use before applies again)
// with one warning naming the file; false when there was no such override.
bool drop_stored_xgemm(Device& device, int status) {
  if (device.tuning().clblast.empty() || !detail::restore_clblast_parameters(device.info(), "Xgemm")) return false;
  std::fprintf(stderr,
               "inertialnet: warning: CLBlast failed (%s) with the Xgemm parameters of the tuning file %s; they are "
               "dropped and CLBlast's defaults used. `inertialnet tune` rewrites the file\n",
               clblast_status_name(status).c_str(),
               device_tuning_file(device.info(), device.programs().directory()).string().c_str());
  return true;
}

// One GEMM large enough for CLBlast's indirect Xgemm kernel (the one a tuning file's parameters
// are for), run with standard output captured. CLBlast 1.5 prints a failed build's log on
// standard output itself (fprintf(stdout) in its src/utilities/compile.cpp), where it would land
// in a CSV written there; so the log is dropped, and what else reached standard output meanwhile
// is passed on when the probe succeeds. Called with clblast_mutex held.
int probe_xgemm(Queue& queue) {
  const DeviceInfo& info = queue.device().info();
  // CLBlast takes its direct kernel below XGEMM_MIN_INDIRECT_SIZE³ (its GemmRoutine parameters).
  std::size_t size = 512;
  std::unordered_map<std::string, std::size_t> routine;
  if (clblast::RetrieveParameters(info.device_id, "GemmRoutine", clblast::Precision::kSingle, routine) ==
          clblast::StatusCode::kSuccess &&
      routine.count("XGEMM_MIN_INDIRECT_SIZE")) {
    size = std::clamp<std::size_t>((routine["XGEMM_MIN_INDIRECT_SIZE"] + 63) / 64 * 64, 64, 4096);
  }
  const std::size_t floats = size * size;
  const std::shared_ptr<Buffer> a = queue.buffers().acquire(floats * sizeof(float));
  const std::shared_ptr<Buffer> b = queue.buffers().acquire(floats * sizeof(float));
  const std::shared_ptr<Buffer> c = queue.buffers().acquire(floats * sizeof(float));
  cl_command_queue handle = queue.handle();

  std::cout.flush();
  std::fflush(stdout);
  std::FILE* capture = std::tmpfile();
  const int saved = capture ? ::dup(STDOUT_FILENO) : -1;
  const bool redirected = saved >= 0 && ::dup2(::fileno(capture), STDOUT_FILENO) >= 0;
  std::size_t temp_bytes = 0;
  auto status = clblast::GemmTempBufferSize<float>(clblast::Layout::kRowMajor, clblast::Transpose::kNo,
                                                   clblast::Transpose::kNo, size, size, size, 0, size, 0, size, 0,
                                                   size, &handle, temp_bytes);
  if (status == clblast::StatusCode::kSuccess) {
    const std::shared_ptr<Buffer> temp = temp_bytes > 0 ? queue.buffers().acquire(temp_bytes) : nullptr;
    status = clblast::Gemm<float>(clblast::Layout::kRowMajor, clblast::Transpose::kNo, clblast::Transpose::kNo, size,
                                  size, size, 1.0f, a->handle(), 0, size, b->handle(), 0, size, 0.0f, c->handle(), 0,
                                  size, &handle, nullptr, temp ? temp->handle() : nullptr);
    if (status == clblast::StatusCode::kSuccess) clFinish(handle);  // the buffers go back to the pool
  }
  std::fflush(stdout);
  if (redirected) ::dup2(saved, STDOUT_FILENO);
  if (saved >= 0) ::close(saved);
  if (capture) {
    if (redirected && status == clblast::StatusCode::kSuccess) {
      std::rewind(capture);
      char chunk[4096];
      for (std::size_t n; (n = std::fread(chunk, 1, sizeof chunk, capture)) > 0;) std::fwrite(chunk, 1, n, stdout);
      std::fflush(stdout);
    }
    std::fclose(capture);
  }
  return static_cast<int>(status);
}

// Runs `call` (one CLBlast routine, returning its status). A tuning file's Xgemm set that passed
// the checks of runtime/device_tuning.cpp but that CLBlast still cannot build must only cost
// speed (docs/performance.md): the first call on a device with such a set is preceded by
// probe_xgemm, and a failing probe or call drops the set (drop_stored_xgemm) and the call is made
// again on the defaults. Without an override the status is returned as is. Called with
// clblast_mutex held.
template <typename Call>
int call_clblast(Queue& queue, Call call) {
  Device& device = queue.device();
  static std::set<cl_device_id> probed;
  if (!device.tuning().clblast.empty() && probed.insert(device.info().device_id).second) {
    const int probe = probe_xgemm(queue);
    if (probe != 0) drop_stored_xgemm(device, probe);
  }
  const int status = static_cast<int>(call());
  if (status == 0 || !drop_stored_xgemm(device, status)) return status;
  return static_cast<int>(call());
}

clblast::Transpose to_clblast(Transpose t) { return t == Transpose::Yes ? clblast::Transpose::kYes : clblast::Transpose::kNo; }

void check_problem(Transpose ta, Transpose tb, std::size_t m, std::size_t n, std::size_t k, const MatrixView& a,
                   std::size_t sa, const MatrixView& b, std::size_t sb, const MatrixView& c, std::size_t sc,
                   std::size_t batch) {
  if (m == 0 || n == 0 || k == 0 || batch == 0) {
    throw invalid_input("GEMM with an empty dimension: m=" + std::to_string(m) + " n=" + std::to_string(n) +
                        " k=" + std::to_string(k) + " batch=" + std::to_string(batch));
  }
  // As stored (row-major): A is m×k, or k×m when transposed; likewise B.
  detail::check_gemm_operand("A", a, ta == Transpose::No ? m : k, ta == Transpose::No ? k : m, sa, batch);
  detail::check_gemm_operand("B", b, tb == Transpose::No ? k : n, tb == Transpose::No ? n : k, sb, batch);
  detail::check_gemm_operand("C", c, m, n, sc, batch);
}

}  // namespace

MatrixView MatrixView::of(const Tensor& tensor, std::size_t leading_dimension, std::size_t extra_offset) {
  return MatrixView{tensor.buffer(), tensor.offset() + extra_offset, leading_dimension, tensor.buffer_floats()};
}

void gemm(Queue& queue, Transpose transpose_a, Transpose transpose_b, std::size_t m, std::size_t n, std::size_t k,
          float alpha, const MatrixView& a, const MatrixView& b, float beta, const MatrixView& c) {
  gemm(queue, gemm_backend(queue.device().info()), transpose_a, transpose_b, m, n, k, alpha, a, b, beta, c);
}

void gemm(Queue& queue, GemmBackend backend, Transpose transpose_a, Transpose transpose_b, std::size_t m,
          std::size_t n, std::size_t k, float alpha, const MatrixView& a, const MatrixView& b, float beta,
          const MatrixView& c) {
  check_problem(transpose_a, transpose_b, m, n, k, a, 0, b, 0, c, 0, 1);
  if (uses_packed_kernels(backend)) {
    const PackedPanels packed_a = pack_a(queue, transpose_a, m, k, a);
    const PackedPanels packed_b = pack_b(queue, transpose_b, k, n, b);
    gemm_packed(queue, packed_a, packed_b, c, GemmEpilogue{alpha, beta, Tensor(), ActivationSpec::none()});
    return;
  }
  cl_command_queue handle = queue.handle();
  const ClSite site = queue.device().site("clblast/Xgemm");
  std::lock_guard<std::mutex> lock(clblast_mutex());
  // CLBlast's indirect GEMM (sizes off its tiles) pads and transposes the operands into a
  // temporary buffer; given none, it creates and releases one on every call: a driver allocation
  // and free per layer per pair, churn in the host allocator on CPU devices. The queue's pool
  // lends it instead, the same buffer every time a shape repeats. The in-order queue runs the
  // kernels that use it before any later user of the recycled buffer.
  std::shared_ptr<Buffer> temp;
  const auto attempt = [&]() -> int {
    // The temporary's size depends on the parameters in use: asked again after a fallback.
    std::size_t temp_bytes = 0;
    const auto sized = clblast::GemmTempBufferSize<float>(
        clblast::Layout::kRowMajor, to_clblast(transpose_a), to_clblast(transpose_b), m, n, k, a.offset,
        a.leading_dimension, b.offset, b.leading_dimension, c.offset, c.leading_dimension, &handle, temp_bytes);
    if (sized != clblast::StatusCode::kSuccess) return static_cast<int>(sized);
    temp = temp_bytes > 0 ? queue.buffers().acquire(temp_bytes) : nullptr;
    return static_cast<int>(clblast::Gemm<float>(
        clblast::Layout::kRowMajor, to_clblast(transpose_a), to_clblast(transpose_b), m, n, k, alpha, a.buffer,
        a.offset, a.leading_dimension, b.buffer, b.offset, b.leading_dimension, beta, c.buffer, c.offset,
        c.leading_dimension, &handle, nullptr, temp ? temp->handle() : nullptr));
  };
  const int status = call_clblast(queue, attempt);
  check_clblast(status, "clblast::Gemm", site);
}

void gemm_strided_batched(Queue& queue, Transpose transpose_a, Transpose transpose_b, std::size_t m, std::size_t n,
                          std::size_t k, float alpha, const MatrixView& a, std::size_t stride_a, const MatrixView& b,
                          std::size_t stride_b, float beta, const MatrixView& c, std::size_t stride_c,
                          std::size_t batch) {
  check_problem(transpose_a, transpose_b, m, n, k, a, stride_a, b, stride_b, c, stride_c, batch);
  const GemmBackend backend = gemm_backend(queue.device().info());
  if (batch == 1 || uses_packed_kernels(backend)) {
    // The packed kernels have no batched form: one product per batch entry.
    for (std::size_t i = 0; i < batch; ++i) {
      auto at = [i](MatrixView view, std::size_t stride) {
        view.offset += i * stride;
        return view;
      };
      gemm(queue, backend, transpose_a, transpose_b, m, n, k, alpha, at(a, stride_a), at(b, stride_b), beta,
           at(c, stride_c));
    }
    return;
  }
  cl_command_queue handle = queue.handle();
  std::lock_guard<std::mutex> lock(clblast_mutex());
  const int status = call_clblast(queue, [&] {
    return clblast::GemmStridedBatched<float>(
        clblast::Layout::kRowMajor, to_clblast(transpose_a), to_clblast(transpose_b), m, n, k, alpha, a.buffer,
        a.offset, a.leading_dimension, stride_a, b.buffer, b.offset, b.leading_dimension, stride_b, beta, c.buffer,
        c.offset, c.leading_dimension, stride_c, batch, &handle, nullptr);
  });
  check_clblast(status, "clblast::GemmStridedBatched", queue.device().site("clblast/XgemmStridedBatched"));
}

}  // namespace inertialnet
