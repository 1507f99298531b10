// SPDX-License-Identifier: Apache-2.0
// SGEMM on FlowNet2's layer shapes, interleaved in one process: the packed-panel kernels,
// CLBlast on the same device, and OpenBLAS on the host (loaded at run time, so the library never
// links it and this benchmark runs without it). Rounds alternate the three so machine load
// affects them alike; the best wall time of each is reported as GFLOP/s with ours ÷ OpenBLAS.
//
// The packed timing is the product alone: a layer's weights are packed once when the model
// loads and im2col writes the B panels directly, so neither is part of a convolution's GEMM.
//
// usage: bench_gemm_packed [--rounds R] [--reps N] [--mr MR] [M,N,K ...]
// Environment: INERTIALNET_DEVICE, OPENBLAS_NUM_THREADS (default 2), INERTIALNET_OPENBLAS
// (the library's path, default libopenblas.so.0).
#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "inertialnet/inertialnet.hpp"

namespace {

using namespace inertialnet;
using Clock = std::chrono::steady_clock;

struct Shape3 {
  std::size_t m, n, k;
  const char* layer;
};

// (output channels, output pixels, input channels × kernel area) at 512×384.
const std::vector<Shape3> kFlowNet2Shapes{
    {1024, 1024, 1024, "square"},
    {128, 49152, 576, "conv1_1 (SD, fusion)"},
    {256, 3072, 4257, "FlowNetC conv3_1"},
    {128, 12288, 1600, "conv2 5x5 s2"},
    {256, 3072, 3200, "conv3 5x5 s2"},
    {512, 768, 2304, "conv4 3x3 s2"},
    {16, 196608, 738, "fusion inter_conv0"},
    {32, 49152, 1458, "fusion inter_conv1"},
    {1024, 48, 9216, "conv6_1"},
    {2, 12288, 1746, "predict_flow2"},
};

// cblas_sgemm through dlopen: CblasRowMajor = 101, CblasNoTrans = 111.
using Sgemm = void (*)(int, int, int, int, int, int, float, const float*, int, const float*, int, float, float*, int);

Sgemm load_openblas() {
  setenv("OPENBLAS_NUM_THREADS", "2", 0);
  const char* path = std::getenv("INERTIALNET_OPENBLAS");
  void* handle = dlopen(path ? path : "libopenblas.so.0", RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    std::fprintf(stderr, "# OpenBLAS not loaded (%s): its column stays empty\n", dlerror());
    return nullptr;
  }
  return reinterpret_cast<Sgemm>(dlsym(handle, "cblas_sgemm"));
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

template <class Run>
double best_of(int reps, Run&& run) {
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    const auto start = Clock::now();
    run();
    best = std::min(best, seconds_since(start));
  }
  return best;
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 2, reps = 3, mr = 0;
  std::vector<Shape3> shapes;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--rounds" && i + 1 < argc) {
      rounds = std::atoi(argv[++i]);
    } else if (arg == "--reps" && i + 1 < argc) {
      reps = std::atoi(argv[++i]);
    } else if (arg == "--mr" && i + 1 < argc) {
      mr = std::atoi(argv[++i]);
    } else {
      Shape3 s{0, 0, 0, "given"};
      if (std::sscanf(arg.c_str(), "%zu,%zu,%zu", &s.m, &s.n, &s.k) != 3) {
        std::fprintf(stderr, "usage: %s [--rounds R] [--reps N] [--mr MR] [M,N,K ...]\n", argv[0]);
        return 2;
      }
      shapes.push_back(s);
    }
  }
  if (shapes.empty()) shapes = kFlowNet2Shapes;

  try {
    const Sgemm openblas = load_openblas();
    const auto info = select_device(device_spec_or_environment(""), discover_devices());
    Device device(info);
    Queue& queue = device.queue();
    std::printf("# device: %s; load average at start: %s; OPENBLAS_NUM_THREADS=%s\n", info.name.c_str(),
                load_average().c_str(), std::getenv("OPENBLAS_NUM_THREADS"));
    std::printf("%-22s %6s %7s %6s | %9s %9s %9s | %7s %7s | %s\n", "layer", "M", "N", "K", "packed", "CLBlast",
                "OpenBLAS", "pk/OB", "pk/CLB", "max rel. diff packed vs CLBlast");

    for (const Shape3& s : shapes) {
      std::vector<float> a(s.m * s.k), b(s.k * s.n), c(s.m * s.n);
      for (std::size_t i = 0; i < a.size(); ++i) a[i] = std::sin(0.37f * static_cast<float>(i % 1013));
      for (std::size_t i = 0; i < b.size(); ++i) b[i] = std::cos(0.11f * static_cast<float>(i % 997));
      Tensor ta = Tensor::from_host(queue, {static_cast<std::int64_t>(a.size())}, a);
      Tensor tb = Tensor::from_host(queue, {static_cast<std::int64_t>(b.size())}, b);
      Tensor tc = Tensor::empty(queue, {static_cast<std::int64_t>(c.size())});
      Tensor tc_clblast = Tensor::empty(queue, {static_cast<std::int64_t>(c.size())});
      const PackedPanels pa = pack_a(queue, Transpose::No, s.m, s.k, MatrixView::of(ta, s.k), mr);
      const PackedPanels pb = pack_b(queue, Transpose::No, s.k, s.n, MatrixView::of(tb, s.n));

      auto run_packed = [&] {
        gemm_packed(queue, pa, pb, MatrixView::of(tc, s.n));
        queue.finish();
      };
      auto run_clblast = [&] {
        gemm(queue, GemmBackend::CLBlast, Transpose::No, Transpose::No, s.m, s.n, s.k, 1.0f, MatrixView::of(ta, s.k),
             MatrixView::of(tb, s.n), 0.0f, MatrixView::of(tc_clblast, s.n));
        queue.finish();
      };
      auto run_openblas = [&] {
        openblas(101, 111, 111, static_cast<int>(s.m), static_cast<int>(s.n), static_cast<int>(s.k), 1.0f, a.data(),
                 static_cast<int>(s.k), b.data(), static_cast<int>(s.n), 0.0f, c.data(), static_cast<int>(s.n));
      };
      run_packed();  // compile and warm up
      run_clblast();
      if (openblas) run_openblas();
      double packed = 1e30, clblast = 1e30, blas = 1e30;
      for (int r = 0; r < rounds; ++r) {
        if (openblas) {
          blas = std::min(blas, best_of(reps, run_openblas));
          // OpenBLAS's threads spin a while after a call; let them sleep before PoCL's run.
          std::this_thread::sleep_for(std::chrono::milliseconds(300));
        }
        clblast = std::min(clblast, best_of(reps, run_clblast));
        packed = std::min(packed, best_of(reps, run_packed));
      }
      const auto got = tc.to_host(queue), want = tc_clblast.to_host(queue);
      double diff = 0.0, scale = 0.0;
      for (std::size_t i = 0; i < got.size(); ++i) {
        diff = std::max(diff, static_cast<double>(std::fabs(got[i] - want[i])));
        scale = std::max(scale, static_cast<double>(std::fabs(want[i])));
      }
      const double gflop = 2.0 * static_cast<double>(s.m) * s.n * s.k * 1e-9;
      std::printf("%-22s %6zu %7zu %6zu | %9.1f %9.1f %9.1f | %7.2f %7.2f | %.1e\n", s.layer, s.m, s.n, s.k,
                  gflop / packed, gflop / clblast, openblas ? gflop / blas : 0.0, openblas ? blas / packed : 0.0,
                  clblast / packed, scale > 0 ? diff / scale : diff);
      std::fflush(stdout);
    }
    std::printf("# GFLOP/s (best wall time); load average at end: %s\n", load_average().c_str());
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_gemm_packed: %s\n", e.what());
    return e.kind() == ErrorKind::InvalidInput ? 2 : 1;
  }
  return 0;
}
