// SPDX-License-Identifier: Apache-2.0
// Devices, queues, embedded kernels and tensors on the real OpenCL platform (PoCL in CI).
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "support/testing.hpp"

namespace inertialnet {
namespace {

using testing::test_device;
using testing::test_queue;

TEST(Discovery, FindsTheDeviceUnderTest) {
  const auto devices = discover_devices();
  ASSERT_FALSE(devices.empty());
  for (std::size_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(devices[i].index, static_cast<int>(i));
    EXPECT_FALSE(devices[i].name.empty());
    EXPECT_GT(devices[i].compute_units, 0u);
    EXPECT_GT(devices[i].global_memory_bytes, 0u);
    EXPECT_GE(devices[i].opencl_c_major, 1);
  }
  const std::string table = format_device_table(devices);
  EXPECT_NE(table.find(devices[0].name), std::string::npos);
  EXPECT_NE(format_device_json(devices).find("\"opencl_c_version\""), std::string::npos);
}

TEST(Programs, BuildOptionsFollowTheDevice) {
  const auto& info = test_device().info();
  const std::string options = test_device().programs().build_options("-DX=1");
  EXPECT_NE(options.find("-cl-std=CL" + std::to_string(info.opencl_c_major) + "." + std::to_string(info.opencl_c_minor)),
            std::string::npos)
      << options;
  EXPECT_EQ(options.find("INERTIALNET_FP16") != std::string::npos, info.fp16) << options;
  EXPECT_NE(options.find("-DX=1"), std::string::npos);
}

TEST(EmbeddedKernels, AreListedAndCarryTheirSource) {
  const auto families = embedded_kernel_families();
  EXPECT_NE(std::find(families.begin(), families.end(), "elementwise"), families.end());
  EXPECT_NE(embedded_kernel_source("elementwise").find("__kernel void fill"), std::string::npos);
  EXPECT_THROW(embedded_kernel_source("nosuch"), Error);
}

// A kernel file's `#include "common.cl"` is replaced by the shared helpers when embedded; the
// helper file itself is not a family.
TEST(EmbeddedKernels, InlineTheSharedHelpers) {
  const auto families = embedded_kernel_families();
  EXPECT_EQ(std::find(families.begin(), families.end(), "common"), families.end());
  for (const char* family : {"bias_activation", "col2im", "correlation", "elementwise"}) {
    const std::string_view source = embedded_kernel_source(family);
    EXPECT_NE(source.find("#define ACTIVATE"), std::string::npos) << family;
    EXPECT_EQ(source.find("#include"), std::string::npos) << family;
  }
}

TEST(KernelDefines, SpellEachValueOneWay) {
  EXPECT_EQ(KernelDefines().str(), "");
  EXPECT_EQ(KernelDefines().add("KH", std::size_t{3}).add("PAD", -1).add("HAS_BIAS", true).str(),
            "-DKH=3 -DPAD=-1 -DHAS_BIAS=1");
  EXPECT_EQ(KernelDefines().add("NEGATIVE_SLOPE", 0.5f).add(KernelDefines().add("X", false)).str(),
            "-DNEGATIVE_SLOPE=0x1p-1f -DX=0");
}

// An embedded kernel round trip on a size that is not a multiple of the work-group size.
TEST(EmbeddedKernels, RoundTripThroughTheDevice) {
  Queue& queue = test_queue();
  const int count = 1000 + 37;
  const auto a = testing::random_vector(count, 1);
  const auto b = testing::random_vector(count, 2);
  Tensor ta = Tensor::from_host(queue, {count}, a);
  Tensor tb = Tensor::from_host(queue, {count}, b);
  Tensor out = Tensor::empty(test_device(), {count});
  Kernel& axpby = queue.kernel("elementwise", "axpby");
  axpby.set_args(out, ta, tb, count, 2.0f, -0.5f);
  queue.launch(axpby, count, 64);
  const auto result = out.to_host(queue);
  std::vector<float> expected(count);
  for (int i = 0; i < count; ++i) expected[i] = 2.0f * a[i] - 0.5f * b[i];
  // Two roundings at most (fma or not): a few ulps.
  EXPECT_TRUE(testing::all_close(result, expected, 1e-6));
}

TEST(Queues, KernelsAreCreatedOncePerQueue) {
  Queue& queue = test_queue();
  Kernel& first = queue.kernel("elementwise", "fill");
  Kernel& second = queue.kernel("elementwise", "fill");
  EXPECT_EQ(&first, &second);
  auto other = test_device().create_queue(true);
  Kernel& third = other->kernel("elementwise", "fill");
  EXPECT_NE(&first, &third);
  Tensor t = Tensor::empty(test_device(), {5});
  third.set_args(t, 5, 3.5f);
  Event event = other->launch(third, 5, {}, true);
  EXPECT_GE(event.duration_ns(), 0u);
  EXPECT_EQ(t.to_host(*other), std::vector<float>(5, 3.5f));
}

TEST(Queues, CrossQueueDependenciesOrderWork) {
  auto producer = test_device().create_queue();
  auto consumer = test_device().create_queue();
  const int count = 4096;
  Tensor t = Tensor::empty(test_device(), {count});
  Tensor u = Tensor::empty(test_device(), {count});
  Kernel& fill = producer->kernel("elementwise", "fill");
  fill.set_args(t, count, 7.0f);
  producer->launch(fill, count);
  const Event done = producer->marker();
  producer->flush();
  consumer->wait_for(done);
  Kernel& scale = consumer->kernel("elementwise", "scale");
  scale.set_args(u, t, count, 2.0f);
  consumer->launch(scale, count);
  EXPECT_EQ(u.to_host(*consumer), std::vector<float>(count, 14.0f));
}

TEST(Errors, AFailedLaunchNamesTheCallTheErrorTheDeviceAndTheKernel) {
  Queue& queue = test_queue();
  Kernel& fill = queue.kernel("elementwise", "fill");
  Tensor t = Tensor::empty(test_device(), {8});
  fill.set_args(t, 8, 1.0f);
  // A work-group larger than any device allows.
  const std::size_t too_big = test_device().info().max_work_group_size * 2;
  try {
    queue.launch(fill, too_big, too_big);
    FAIL() << "oversized work-group accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.kind(), ErrorKind::Runtime);
    EXPECT_NE(message.find("clEnqueueNDRangeKernel"), std::string::npos) << message;
    EXPECT_NE(message.find("CL_INVALID_WORK_GROUP_SIZE"), std::string::npos) << message;
    EXPECT_NE(message.find(test_device().info().name), std::string::npos) << message;
    EXPECT_NE(message.find("elementwise/fill"), std::string::npos) << message;
  }
}

// Sizes are narrowed to the kernels' int by set_args; one that does not fit is refused by name.
TEST(Errors, ArgumentsTooLargeForAnIntAreRefused) {
  Queue& queue = test_queue();
  Kernel& fill = queue.kernel("elementwise", "fill");
  Tensor t = Tensor::empty(test_device(), {8});
  fill.set_args(t, std::size_t{8}, 1.0f);
  queue.launch(fill, 8);
  EXPECT_EQ(t.to_host(queue), std::vector<float>(8, 1.0f));
  testing::expect_invalid_input([&] { fill.set_args(t, std::size_t{1} << 31, 1.0f); },
                                "kernel elementwise/fill: argument 2 = 2147483648 does not fit");
  testing::expect_invalid_input([&] { fill.set_args(t, -(std::int64_t{1} << 40), 1.0f); }, "elementwise/fill");
}

TEST(Errors, UnknownKernelNamesAreReported) {
  try {
    test_queue().kernel("elementwise", "no_such_kernel");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("CL_INVALID_KERNEL_NAME"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("elementwise/no_such_kernel"), std::string::npos) << e.what();
  }
}

TEST(Tensors, ChannelViewsAndSamplesAddressTheRightElements) {
  Queue& queue = test_queue();
  const Shape shape{3, 5, 4, 7};  // N C H W
  std::vector<float> data(static_cast<std::size_t>(element_count(shape)));
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<float>(i);
  Tensor t = Tensor::from_host(queue, shape, data);
  EXPECT_TRUE(t.contiguous());

  Tensor middle = t.channels(1, 3);
  EXPECT_EQ(middle.shape(), (Shape{3, 3, 4, 7}));
  EXPECT_FALSE(middle.contiguous());
  const auto got = middle.to_host(queue);
  std::size_t k = 0;
  for (int n = 0; n < 3; ++n)
    for (int c = 1; c < 4; ++c)
      for (int i = 0; i < 4 * 7; ++i) ASSERT_EQ(got[k++], data[(n * 5 + c) * 28 + i]);

  // Writing through a view touches only its elements.
  std::vector<float> minus(static_cast<std::size_t>(middle.numel()), -1.0f);
  middle.upload(queue, minus.data(), minus.size());
  const auto after = t.to_host(queue);
  for (std::size_t i = 0; i < after.size(); ++i) {
    const std::size_t c = (i / 28) % 5;
    EXPECT_EQ(after[i], c >= 1 && c <= 3 ? -1.0f : data[i]) << i;
  }

  Tensor second = t.sample(2);
  EXPECT_EQ(second.shape(), (Shape{1, 5, 4, 7}));
  EXPECT_EQ(second.offset(), 2u * 140u);
  EXPECT_THROW(t.channels(4, 2), Error);
  EXPECT_THROW(t.sample(3), Error);
  EXPECT_THROW(middle.reshaped({3 * 3 * 28}), Error);
  EXPECT_EQ(t.reshaped({15, 28}).dim(1), 28);
}

TEST(Tensors, BadShapesAndTransfersAreRefused) {
  EXPECT_THROW(Tensor::empty(test_device(), {}), Error);
  EXPECT_THROW(Tensor::empty(test_device(), {2, 0, 3}), Error);
  Tensor t = Tensor::empty(test_device(), {4});
  std::vector<float> three(3);
  EXPECT_THROW(t.upload(test_queue(), three.data(), three.size()), Error);
  EXPECT_THROW(t.download(test_queue(), three.data(), three.size()), Error);
}

TEST(BufferPool, ReusesReleasedBuffers) {
  BufferPool& pool = test_device().buffers();
  pool.trim();
  const auto before = pool.stats();
  { auto a = pool.acquire(1 << 20); }
  auto b = pool.acquire((1 << 20) - 100);  // fits in the released buffer
  const auto after = pool.stats();
  EXPECT_EQ(after.allocations, before.allocations + 1);
  EXPECT_EQ(after.reuses, before.reuses + 1);
  EXPECT_EQ(b->bytes(), std::size_t{1} << 20);
  auto c = pool.acquire(4 << 20);  // too large for anything idle
  EXPECT_EQ(pool.stats().allocations, before.allocations + 2);
  EXPECT_THROW(pool.acquire(0), Error);
}

// What keeps a long run's memory flat: a pattern of acquisitions and releases repeated (one
// frame pair after another) allocates only in its first round; later rounds reuse exactly those
// buffers, and the idle ones total no more than the first round allocated.
TEST(BufferPool, ARepeatedPatternAllocatesOnlyInItsFirstRound) {
  BufferPool pool(test_device().context(), test_device().info().name, test_device().info().max_alloc_bytes);
  // Sizes of a network's temporaries, some alive across others, some reusable by smaller ones.
  const std::size_t sizes[] = {48 << 20, 12 << 20, 47 << 20, 3 << 20, 20 << 20, 9 << 20, 1 << 20, 25 << 20};
  auto round = [&] {
    std::vector<std::shared_ptr<Buffer>> alive;
    for (std::size_t i = 0; i < std::size(sizes); ++i) {
      alive.push_back(pool.acquire(sizes[i] / 64));  // scaled down: the pattern is what counts
      if (i % 3 == 2) alive.erase(alive.begin());    // the oldest is released
    }
  };
  round();
  const BufferPoolStats first = pool.stats();
  EXPECT_EQ(first.bytes_in_use, 0u);
  for (int i = 0; i < 50; ++i) round();
  const BufferPoolStats later = pool.stats();
  EXPECT_EQ(later.allocations, first.allocations);
  EXPECT_EQ(later.bytes_cached, first.bytes_cached);
  EXPECT_EQ(later.peak_bytes_in_use, first.peak_bytes_in_use);
  EXPECT_EQ(later.reuses, first.reuses + 50 * std::size(sizes));
}

}  // namespace
}  // namespace inertialnet
