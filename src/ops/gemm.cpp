#include "inertialnet/ops/gemm.hpp"

#include <clblast.h>

#include <cstdio>
#include <mutex>

#include "inertialnet/ops/gemm_packed.hpp"
#include "inertialnet/runtime/device.hpp"
#include "ops/gemm_support.hpp"
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

// Runs `call` (one CLBlast routine, returning its status). When it fails and the device's
// tuning file had overridden CLBlast's Xgemm parameters, those are dropped for the rest of the
// process with one warning naming the file, and the call is made again on the defaults: a stored
// set that passed the checks of runtime/device_tuning.cpp but that CLBlast still cannot build
// must only cost speed (docs/performance.md). Without an override the status is returned as is.
template <typename Call>
int call_clblast(Queue& queue, Call call) {
  int status = static_cast<int>(call());
  if (status == 0) return status;
  Device& device = queue.device();
  if (device.tuning().clblast.empty() || !detail::restore_clblast_parameters(device.info(), "Xgemm")) return status;
  std::fprintf(stderr,
               "inertialnet: warning: CLBlast failed (%s) with the Xgemm parameters of the tuning file %s; they are "
               "dropped and CLBlast's defaults used. `inertialnet tune` rewrites the file\n",
               clblast_status_name(status).c_str(),
               device_tuning_file(device.info(), device.programs().directory()).string().c_str());
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
