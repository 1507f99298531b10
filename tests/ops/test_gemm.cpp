// SPDX-License-Identifier: Apache-2.0
// The CLBlast GEMM wrapper against the plain C++ loop of tests/reference.
#include <clblast.h>

#include "reference/gemm.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

struct GemmCase {
  std::size_t m, n, k;
  bool ta, tb;
  std::size_t pad;     // extra columns in every leading dimension
  std::size_t offset;  // elements before each operand
};

class GemmTest : public ::testing::TestWithParam<GemmCase> {};

TEST_P(GemmTest, MatchesTheReference) {
  const GemmCase p = GetParam();
  Queue& queue = testing::test_queue();
  // Stored shapes (row-major): A is m×k or k×m, B is k×n or n×k, C is m×n.
  const std::size_t a_rows = p.ta ? p.k : p.m, a_cols = p.ta ? p.m : p.k;
  const std::size_t b_rows = p.tb ? p.n : p.k, b_cols = p.tb ? p.k : p.n;
  const std::size_t lda = a_cols + p.pad, ldb = b_cols + p.pad, ldc = p.n + p.pad;
  const auto a = testing::random_vector(p.offset + a_rows * lda, 11);
  const auto b = testing::random_vector(p.offset + b_rows * ldb, 12);
  auto c = testing::random_vector(p.offset + p.m * ldc, 13);
  Tensor ta = Tensor::from_host(queue, {static_cast<std::int64_t>(a.size())}, a);
  Tensor tb = Tensor::from_host(queue, {static_cast<std::int64_t>(b.size())}, b);
  Tensor tc = Tensor::from_host(queue, {static_cast<std::int64_t>(c.size())}, c);

  gemm(queue, p.ta ? Transpose::Yes : Transpose::No, p.tb ? Transpose::Yes : Transpose::No, p.m, p.n, p.k, 1.5f,
       MatrixView::of(ta, lda, p.offset), MatrixView::of(tb, ldb, p.offset), 0.5f, MatrixView::of(tc, ldc, p.offset));
  reference::gemm(p.ta, p.tb, p.m, p.n, p.k, 1.5f, a, p.offset, lda, b, p.offset, ldb, 0.5f, c, p.offset, ldc);
  // float32 accumulation over k terms of size ~1 against a double reference: error grows
  // like sqrt(k)·eps relative to the typical magnitude sqrt(k); 1e-5 absolute per sqrt(k).
  const double floor = std::sqrt(static_cast<double>(p.k));
  EXPECT_TRUE(testing::all_close(tc.to_host(queue), c, 1e-5, floor));
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, GemmTest,
    ::testing::Values(GemmCase{1, 1, 1, false, false, 0, 0}, GemmCase{17, 23, 29, false, false, 0, 0},
                      GemmCase{17, 23, 29, true, false, 3, 5}, GemmCase{17, 23, 29, false, true, 1, 7},
                      GemmCase{33, 65, 47, true, true, 2, 1}, GemmCase{64, 48, 147, false, false, 0, 0},
                      // FlowNetC conv1 at 64×64: 64 filters, 3·7·7 taps, 32·32 outputs.
                      GemmCase{64, 1024, 147, false, false, 0, 0}, GemmCase{3, 1000, 128, false, true, 0, 0}));

// CLBlast's indirect GEMM (large products, here 1100³: above the direct-kernel limit CLBlast's
// database gives PoCL's CPU device) needs a temporary buffer; it comes from the queue's pool, allocated on
// the first call of a shape and reused by every later one (CLBlast would otherwise create and
// release one per call), and it is back in the pool when the call returns.
TEST(GemmClblast, TemporaryBufferComesFromTheQueuesPool) {
  const auto queue = testing::test_device().create_queue();  // a pool of its own
  const std::size_t m = 1100, n = 1100, k = 1100;
  const auto a = testing::random_vector(m * k, 31);
  const auto b = testing::random_vector(k * n, 32);
  auto c = testing::random_vector(m * n, 33);
  Tensor ta = Tensor::from_host(*queue, {static_cast<std::int64_t>(a.size())}, a);
  Tensor tb = Tensor::from_host(*queue, {static_cast<std::int64_t>(b.size())}, b);
  Tensor tc = Tensor::from_host(*queue, {static_cast<std::int64_t>(c.size())}, c);
  auto run = [&] {
    gemm(*queue, GemmBackend::CLBlast, Transpose::No, Transpose::No, m, n, k, 1.0f, MatrixView::of(ta, k),
         MatrixView::of(tb, n), 0.0f, MatrixView::of(tc, n));
    queue->finish();
    return queue->buffers().stats();
  };
  // Whether this device takes the indirect path at this size is CLBlast's choice (an H100 runs
  // 1100³ with its direct kernel and needs no buffer): then nothing may be taken from the pool.
  cl_command_queue handle = queue->handle();
  std::size_t temp_bytes = 0;
  ASSERT_EQ(clblast::GemmTempBufferSize<float>(clblast::Layout::kRowMajor, clblast::Transpose::kNo,
                                               clblast::Transpose::kNo, m, n, k, 0, k, 0, n, 0, n, &handle, temp_bytes),
            clblast::StatusCode::kSuccess);
  const std::size_t lent = temp_bytes > 0 ? 1 : 0;
  const BufferPoolStats before = queue->buffers().stats();
  const BufferPoolStats first = run();
  EXPECT_EQ(first.allocations, before.allocations + lent);
  EXPECT_EQ(first.bytes_in_use, before.bytes_in_use);
  EXPECT_EQ(first.bytes_cached > before.bytes_cached, lent == 1);
  for (std::size_t i = 1; i <= 3; ++i) {
    const BufferPoolStats again = run();
    EXPECT_EQ(again.allocations, first.allocations);
    EXPECT_EQ(again.reuses, first.reuses + i * lent);
    EXPECT_EQ(again.bytes_cached, first.bytes_cached);
  }
  // The result through the lent buffer, on the first rows (the reference loop is slow).
  const std::size_t rows = 4;
  reference::gemm(false, false, rows, n, k, 1.0f, a, 0, k, b, 0, n, 0.0f, c, 0, n);
  const auto result = tc.to_host(*queue);
  EXPECT_TRUE(testing::all_close(std::vector<float>(result.begin(), result.begin() + rows * n),
                                 std::vector<float>(c.begin(), c.begin() + rows * n), 1e-5, std::sqrt(double(k))));
}

TEST(GemmBatched, StridedBatchesMatchTheReference) {
  Queue& queue = testing::test_queue();
  const std::size_t m = 13, n = 19, k = 21, batch = 3;
  const std::size_t sa = m * k + 4, sb = k * n + 2, sc = m * n + 5;
  const auto a = testing::random_vector(sa * batch, 21);
  const auto b = testing::random_vector(sb * batch, 22);
  auto c = testing::random_vector(sc * batch, 23);
  Tensor ta = Tensor::from_host(queue, {static_cast<std::int64_t>(a.size())}, a);
  Tensor tb = Tensor::from_host(queue, {static_cast<std::int64_t>(b.size())}, b);
  Tensor tc = Tensor::from_host(queue, {static_cast<std::int64_t>(c.size())}, c);
  gemm_strided_batched(queue, Transpose::No, Transpose::No, m, n, k, 1.0f, MatrixView::of(ta, k), sa,
                       MatrixView::of(tb, n), sb, 0.0f, MatrixView::of(tc, n), sc, batch);
  for (std::size_t i = 0; i < batch; ++i) {
    reference::gemm(false, false, m, n, k, 1.0f, a, i * sa, k, b, i * sb, n, 0.0f, c, i * sc, n);
  }
  EXPECT_TRUE(testing::all_close(tc.to_host(queue), c, 1e-5, std::sqrt(double(k))));
}

TEST(GemmChecks, WrongShapesAreInvalidInputNamingTheOperand) {
  Queue& queue = testing::test_queue();
  Tensor small = Tensor::empty(testing::test_device(), {100});
  Tensor big = Tensor::empty(testing::test_device(), {10000});
  auto expect_error = [&](auto&& call, const std::string& needle) {
    try {
      call();
      FAIL() << "accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  // A is 20×10 but its buffer holds 100 floats.
  expect_error([&] { gemm(queue, Transpose::No, Transpose::No, 20, 10, 10, 1, MatrixView::of(small, 10), MatrixView::of(big, 10), 0, MatrixView::of(big, 10)); },
               "operand A");
  expect_error([&] { gemm(queue, Transpose::No, Transpose::No, 5, 10, 10, 1, MatrixView::of(big, 10), MatrixView::of(big, 5), 0, MatrixView::of(big, 10)); },
               "leading dimension");
  expect_error([&] { gemm(queue, Transpose::No, Transpose::No, 0, 10, 10, 1, MatrixView::of(big, 10), MatrixView::of(big, 10), 0, MatrixView::of(big, 10)); },
               "empty dimension");
  expect_error([&] { gemm_strided_batched(queue, Transpose::No, Transpose::No, 10, 10, 10, 1, MatrixView::of(big, 10), 100, MatrixView::of(big, 10), 100, 0, MatrixView::of(small, 10), 100, 2); },
               "operand C");
}

}  // namespace
}  // namespace inertialnet
