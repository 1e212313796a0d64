#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

#if STVL_TEST_TBB
#include <tbb/parallel_for.h>
#endif

#include "bench/synthetic_corridor.hpp"
#include "filter/filter.hpp"
#include "helpers.hpp"

namespace stvl::filter {
namespace {

TEST(FilterConfig, ParsesNamesAndRejectsOthers) {
  EXPECT_EQ(parse_device("cpu"), Device::kCpu);
  EXPECT_EQ(parse_device("cuda"), Device::kCuda);
  EXPECT_EQ(parse_device("auto"), Device::kAuto);
  EXPECT_EQ(parse_memory_mode("managed"), MemoryMode::kManaged);
  EXPECT_EQ(parse_memory_mode("mapped"), MemoryMode::kMapped);
  EXPECT_EQ(parse_filter_type("csnb"), FilterType::kCsnb);
  EXPECT_STREQ(to_string(MemoryMode::kPinned), "pinned");
  for (FilterType t : {FilterType::kNone, FilterType::kPassthrough, FilterType::kVoxel, FilterType::kCsnb})
    EXPECT_EQ(parse_filter_type(to_string(t)), t);
  for (Device d : {Device::kCpu, Device::kCuda, Device::kAuto}) EXPECT_EQ(parse_device(to_string(d)), d);
  for (MemoryMode m : {MemoryMode::kCopy, MemoryMode::kPinned, MemoryMode::kMapped, MemoryMode::kManaged})
    EXPECT_EQ(parse_memory_mode(to_string(m)), m);
  auto message = [](auto parse, const std::string& text) {
    try {
      parse(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_EQ(message(parse_device, "gpu"), "filter: unknown device 'gpu' (expected cpu|cuda|auto; did you mean 'cpu'?)");
  EXPECT_EQ(message(parse_memory_mode, "Copy"),
            "filter: unknown memory mode 'Copy' (expected copy|pinned|mapped|managed; did you mean 'copy'?)");
  EXPECT_EQ(message(parse_filter_type, ""), "filter: unknown filter type '' (expected none|passthrough|voxel|csnb)");
}

TEST(Filter, PassthroughThenVoxelOnCpu) {
  FilterConfig config;
  config.device = Device::kCpu;
  config.passthrough = {0.2, 0.8};
  config.voxel.voxel_size_m = 0.1;
  Filter filter(config);
  const Eigen::Matrix3Xf cloud = test::random_cloud(2, 10000, 0.f, 1.f);
  const Eigen::Matrix3Xf out = filter.apply(cloud);
  EXPECT_STREQ(filter.device_used(), "cpu");
  EXPECT_TRUE(out.cols() > 0);
  EXPECT_GE(out.row(2).minCoeff(), 0.2f);
  EXPECT_LE(out.row(2).maxCoeff(), 0.8f);
  EXPECT_TRUE(out == voxel_grid(passthrough(cloud, config.passthrough), config.voxel));
  config.voxel.voxel_size_m = -1;
  EXPECT_THROW(Filter{config}, std::invalid_argument);
}

TEST(Filter, WithoutGpuAutoFallsBackAndCudaThrows) {
  if (cuda_available()) GTEST_SKIP() << "a GPU is present";
  FilterConfig config;
  config.device = Device::kAuto;
  EXPECT_STREQ(Filter(config).device_used(), "cpu");
  config.device = Device::kCuda;
  EXPECT_THROW(Filter{config}, std::runtime_error);
}

// Calls from several threads at once, and (with TBB) from inside TBB tasks, give the outputs of sequential
// calls: the per-thread buffers and the parts stay apart.
TEST(Filter, ConcurrentCallsGiveTheSequentialOutputs) {
  constexpr int kClouds = 6;
  std::vector<Eigen::Matrix3Xf> clouds, voxel_expected, csnb_expected;
  const VoxelGridConfig voxel{0.02, 1};
  CsnbConfig csnb_config;
  csnb_config.voxel_size_m = 0.05;
  for (int i = 0; i < kClouds; ++i) {
    clouds.push_back(test::random_cloud(100 + i, 40000 + 5000 * i, -1.f, 1.f));
    voxel_expected.push_back(voxel_grid(clouds[i], voxel, 1));
    csnb_expected.push_back(csnb(clouds[i], csnb_config, 1));
  }
  std::vector<Eigen::Matrix3Xf> voxel_out(2 * kClouds), csnb_out(2 * kClouds);
  auto run_voxel = [&](int k) { voxel_out[k] = voxel_grid(clouds[k % kClouds], voxel, 2); };
  auto run_csnb = [&](int k) { csnb_out[k] = csnb(clouds[k % kClouds], csnb_config, 3); };
  auto run = [&](int k) {
    run_voxel(k);
    run_csnb(k);
  };
  auto check = [&](const char* how) {
    for (int k = 0; k < 2 * kClouds; ++k) {
      EXPECT_TRUE(test::same_bits(voxel_out[k], voxel_expected[k % kClouds])) << how << " voxel call " << k;
      EXPECT_TRUE(test::same_bits(csnb_out[k], csnb_expected[k % kClouds])) << how << " csnb call " << k;
    }
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < 2 * kClouds; ++k) threads.emplace_back(run, k);
  for (auto& thread : threads) thread.join();
  check("std::thread");
#if STVL_TEST_TBB
  tbb::parallel_for(0, 2 * kClouds, run_voxel);
  tbb::parallel_for(0, 2 * kClouds, run_csnb);
  check("tbb::parallel_for");
#endif
}

class CpuVsCuda : public ::testing::TestWithParam<MemoryMode> {};

TEST_P(CpuVsCuda, IdenticalOutputs) {
  std::string reason;
  if (!cuda_available(&reason)) GTEST_SKIP() << "no GPU: " << reason;
  const Eigen::Matrix3Xf corridor = bench::make_corridor_cloud(4, 424, 240);
  Eigen::Matrix3Xf random = test::random_cloud(6, 50000, -2.f, 3.f);
  random(0, 17) = std::numeric_limits<float>::quiet_NaN();
  for (const Eigen::Matrix3Xf* cloud : {&corridor, static_cast<const Eigen::Matrix3Xf*>(&random)}) {
    for (FilterType type : {FilterType::kVoxel, FilterType::kCsnb}) {
      for (double voxel : {0.02, 0.1}) {
        FilterConfig config;
        config.type = type;
        config.passthrough_enabled = false;
        config.memory = GetParam();
        config.voxel = {voxel, 2};
        config.csnb.voxel_size_m = voxel;
        config.csnb.max_neighbours = 3;
        config.csnb.batch_size = 500;
        config.device = Device::kCpu;
        Filter cpu(config);
        config.device = Device::kCuda;
        Filter gpu(config);
        const Eigen::Matrix3Xf expected = cpu.apply(*cloud);
        for (int call = 0; call < 2; ++call) {  // the second call reuses the device buffers
          const Eigen::Matrix3Xf actual = gpu.apply(*cloud);
          ASSERT_EQ(actual.cols(), expected.cols()) << to_string(type) << " " << voxel;
          EXPECT_TRUE(actual == expected) << to_string(type) << " " << voxel;
        }
        EXPECT_STREQ(gpu.device_used(), "cuda");
      }
    }
  }
  FilterConfig bad;
  bad.device = Device::kCuda;
  bad.memory = GetParam();
  Filter gpu(bad);
  Eigen::Matrix3Xf cube(3, 2);
  cube << -5e4f, 5e4f, -5e4f, 5e4f, -5e4f, 5e4f;
  bad.voxel.voxel_size_m = 0.001;
  Filter tiny(bad);
  EXPECT_THROW(tiny.apply(cube), std::invalid_argument);
  EXPECT_EQ(gpu.apply(Eigen::Matrix3Xf(3, 0)).cols(), 0);
}

INSTANTIATE_TEST_SUITE_P(MemoryModes, CpuVsCuda,
                         ::testing::Values(MemoryMode::kCopy, MemoryMode::kPinned, MemoryMode::kMapped,
                                           MemoryMode::kManaged),
                         [](const auto& info) { return std::string(to_string(info.param)); });

// The sort both CSNB orders rest on: stable on the chosen bits, from several segments, for narrow and wide bit
// ranges (one to three passes), with heavy digits and many ties.
TEST(RadixSort, EqualsStableSortOnTheChosenBits) {
  struct Range {
    int low, high;
  };
  for (const Range r : {Range{0, 5}, Range{0, 8}, Range{4, 13}, Range{32, 59}, Range{32, 64}, Range{7, 40}}) {
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, std::size_t{70000}}) {
      std::vector<std::uint64_t> input(n);
      for (std::size_t i = 0; i < n; ++i) {
        const std::uint64_t h = detail::hash3(5, i, std::uint64_t(r.low));
        input[i] = i % 3 == 0 ? (h & 0xFFFF) : h;  // a third share a few keys: heavy buckets and ties
      }
      const std::uint64_t mask =
          r.high - r.low == 64 ? ~std::uint64_t{0} : ((std::uint64_t{1} << (r.high - r.low)) - 1);
      auto key_of = [&](std::uint64_t v) { return (v >> r.low) & mask; };
      std::vector<std::uint64_t> expected = input;
      std::stable_sort(expected.begin(), expected.end(),
                       [&](std::uint64_t x, std::uint64_t y) { return key_of(x) < key_of(y); });
      for (int threads : {1, 3}) {
        // Segments as a filter makes them: parts of the buffer, each a prefix of its part.
        std::vector<std::uint64_t> a(n), b(n);
        std::copy(input.begin(), input.end(), a.begin());
        std::vector<detail::Segment<std::uint64_t>> segments;
        const std::size_t parts = 3;
        for (std::size_t t = 0; t < parts; ++t) {
          const std::size_t lo = n * t / parts, hi = n * (t + 1) / parts;
          segments.push_back({a.data() + lo, hi - lo});
        }
        const std::uint64_t* out = detail::radix_sort_segments(
            segments, a.data(), b.data(), r.low, r.high, [](std::uint64_t v) { return v; }, threads);
        ASSERT_TRUE(std::equal(expected.begin(), expected.end(), out))
            << "bits [" << r.low << ", " << r.high << "), n " << n << ", threads " << threads;
      }
    }
  }
}

}  // namespace
}  // namespace stvl::filter
