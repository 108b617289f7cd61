// Tests of the CrossRT Vulkan runtime on a real device (lavapipe in CI) with validation enabled.
// Shaders are GLSL compiled at test time with glslangValidator.
#include <algorithm>
#include <atomic>
#include <cctype>
#include <catch2/catch.hpp>

#include <crossrt/CpuParallel.h>
#include <crossrt/IspcSupport.h>
#include <crossrt/VulkanRuntime.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#ifndef CROSSRT_GLSLANG_VALIDATOR
#define CROSSRT_GLSLANG_VALIDATOR "glslangValidator"
#endif

#ifdef _WIN32
#define popen _popen
#define pclose _pclose
#include <stdlib.h>
static void setenv(const char* name, const char* value, int) { _putenv_s(name, value); }
static void unsetenv(const char* name) { _putenv_s(name, ""); }
#endif

using namespace crossrt;
namespace fs = std::filesystem;

namespace {

// A directory unique to this test run, for compiled shaders and pipeline caches; removed at exit.
const fs::path& TempDir() {
  struct Dir {
    fs::path path;
    Dir() {
      std::random_device rd;
      path = fs::temp_directory_path() / ("crossrt_runtime_test_" + std::to_string(rd()));
      fs::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

std::vector<uint32_t> CompileGlsl(const std::string& source, const char* stage = "comp") {
  static int counter = 0;
  const fs::path spv = TempDir() / ("shader" + std::to_string(counter) + ".spv");
  const fs::path log = TempDir() / ("shader" + std::to_string(counter) + ".log");
  ++counter;
  const std::string cmd = std::string("\"") + CROSSRT_GLSLANG_VALIDATOR +
                          "\" -V --target-env vulkan1.2 --stdin -S " + stage + " -o \"" + spv.string() + "\" > \"" +
                          log.string() + "\" 2>&1";
  FILE* pipe = popen(cmd.c_str(), "w");
  REQUIRE(pipe != nullptr);
  std::fputs(source.c_str(), pipe);
  const int rc = pclose(pipe);
  if (rc != 0) {
    std::ifstream in(log);
    std::stringstream text;
    text << in.rdbuf();
    FAIL("glslangValidator failed (" << cmd << "):\n" << text.str());
  }
  std::ifstream in(spv, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  REQUIRE(!bytes.empty());
  REQUIRE(bytes.size() % 4 == 0);
  std::vector<uint32_t> words(bytes.size() / 4);
  std::memcpy(words.data(), bytes.data(), bytes.size());
  return words;
}

// Validation on; a missing driver is a visible skip, anything else is a failure.
std::shared_ptr<VulkanContext> MakeContext() {
  // Keep the tests from writing into the user's ~/.cache.
  if (!std::getenv("CROSSRT_PIPELINE_CACHE_DIR"))
    setenv("CROSSRT_PIPELINE_CACHE_DIR", (TempDir() / "cache").string().c_str(), 1);
  ContextOptions options;
  options.validation = true;
  try {
    return VulkanContext::Create(options);
  } catch (const NoDeviceError& e) {
    WARN("skipped, no Vulkan device: " << e.what());
    return nullptr;
  }
}

void RequireNoValidationMessages(const VulkanContext& ctx) {
  for (const std::string& m : ctx.ValidationMessages()) UNSCOPED_INFO("validation: " << m);
  REQUIRE(ctx.ValidationMessageCount() == 0);
}

const char* kSaxpy = R"(#version 450
layout(local_size_x = 256) in;
layout(std430, set = 0, binding = 0) readonly buffer X { float x[]; };
layout(std430, set = 0, binding = 1) buffer Y { float y[]; };
layout(push_constant) uniform Params { float a; uint n; } pc;
void main() {
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  if (i >= pc.n) return;
  precise float r = pc.a * x[i] + y[i];   // no FMA contraction: the CPU reference does not fuse either
  y[i] = r;
}
)";

const char* kCountIds = R"(#version 450
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) buffer Counts { uint counts[]; };
layout(push_constant) uniform Params { uint n; } pc;
void main() {
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  if (id >= pc.n) return;
  atomicAdd(counts[id], 1u);
}
)";

struct SaxpyParams {
  float a;
  uint32_t n;
};

}  // namespace

TEST_CASE("Upload/Download round trip at an offset", "[runtime]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  INFO("device: " << ctx->DeviceName());
  const size_t bytes = 1 << 20, offset = 12345;
  std::mt19937 rng(42);
  std::vector<uint8_t> data(bytes);
  for (auto& b : data) b = static_cast<uint8_t>(rng());

  Buffer buf(ctx, bytes + offset + 100);
  REQUIRE(buf.Size() == bytes + offset + 100);
  buf.Fill(0);
  buf.Upload(data.data(), bytes, offset);
  std::vector<uint8_t> back(bytes);
  buf.Download(back.data(), bytes, offset);
  REQUIRE(back == data);

  // Bytes outside the uploaded range are untouched.
  uint8_t edge[2] = {1, 1};
  buf.Download(&edge[0], 1, offset - 1);
  buf.Download(&edge[1], 1, offset + bytes);
  CHECK(edge[0] == 0);
  CHECK(edge[1] == 0);

  CHECK_THROWS_AS(buf.Upload(data.data(), bytes, 200000), Error);  // out of range: clear error
  RequireNoValidationMessages(*ctx);
}

TEST_CASE("Upload/Download through the staging path", "[runtime]") {
  if (!std::getenv("CROSSRT_PIPELINE_CACHE_DIR"))
    setenv("CROSSRT_PIPELINE_CACHE_DIR", (TempDir() / "cache").string().c_str(), 1);
  ContextOptions options;
  options.validation = true;
  options.forceStaging = true;  // what GPUs without host-visible VRAM do
  std::shared_ptr<VulkanContext> ctx;
  try {
    ctx = VulkanContext::Create(options);
  } catch (const NoDeviceError& e) {
    WARN("skipped, no Vulkan device: " << e.what());
    return;
  }
  const size_t bytes = 300001, offset = 777;
  std::mt19937 rng(7);
  std::vector<uint8_t> data(bytes);
  for (auto& b : data) b = static_cast<uint8_t>(rng());
  Buffer buf(ctx, bytes + offset);
  REQUIRE_FALSE(buf.HostMapped());
  buf.Upload(data.data(), bytes, offset);
  std::vector<uint8_t> back(bytes);
  buf.Download(back.data(), bytes, offset);
  REQUIRE(back == data);

  buf.Fill(0x01020304u);
  uint32_t word = 0;
  buf.Download(&word, 4, 0);
  CHECK(word == 0x01020304u);

  // The context reuses its staging buffers: a smaller copy after a larger one, a larger one that
  // grows them, one past their limit (64 MiB) through a buffer of its own, and copies from two
  // threads at once, each of its own buffer.
  std::vector<uint8_t> small(1000, 0xAB);
  buf.Upload(small.data(), small.size(), 5);
  std::vector<uint8_t> smallBack(1010);
  buf.Download(smallBack.data(), smallBack.size(), 0);
  CHECK(std::vector<uint8_t>(smallBack.begin() + 5, smallBack.begin() + 1005) == small);
  CHECK(smallBack[1005] == 0x03);  // the fill's bytes around it (0x01020304, little-endian)
  CHECK(smallBack[1008] == 0x04);
  for (size_t size : {size_t(3) << 20, (size_t(64) << 20) + 4096}) {
    std::vector<uint8_t> big(size);
    for (size_t i = 0; i < size; ++i) big[i] = static_cast<uint8_t>(i * 2654435761u >> 24);
    Buffer large(ctx, size);
    large.Upload(big.data(), size);
    std::vector<uint8_t> bigBack(size);
    large.Download(bigBack.data(), size);
    CHECK(bigBack == big);
  }
  std::vector<std::thread> threads;
  std::atomic<int> wrong{0};
  for (int t = 0; t < 2; ++t)
    threads.emplace_back([&, t] {
      Buffer mine(ctx, 4096 * 4);
      for (int round = 0; round < 20; ++round) {
        std::vector<uint32_t> values(4096, uint32_t(t * 1000 + round)), got(4096);
        mine.Upload(values.data(), values.size() * 4);
        mine.Download(got.data(), got.size() * 4);
        wrong += got != values;
      }
    });
  for (auto& th : threads) th.join();
  CHECK(wrong == 0);

  // Several downloads with one wait (crossrt::Downloads): odd sizes and offsets land where each
  // asked, a copy of no bytes does nothing, and one past 64 MiB in all takes a buffer of its own.
  {
    Buffer a(ctx, 4099), b(ctx, 1 << 16);
    std::vector<uint8_t> aData(4099), bData(1 << 16);
    for (size_t i = 0; i < aData.size(); ++i) aData[i] = static_cast<uint8_t>(i * 7 + 1);
    for (size_t i = 0; i < bData.size(); ++i) bData[i] = static_cast<uint8_t>(i * 13 + 5);
    a.Upload(aData.data(), aData.size());
    b.Upload(bData.data(), bData.size());
    std::vector<uint8_t> aBack(4099), bBack(1000), untouched(4, 0xEE);
    crossrt::Downloads downloads(ctx);
    downloads.Add(a, aBack.data(), aBack.size());
    downloads.Add(b, bBack.data(), bBack.size(), 333);
    downloads.Add(a, untouched.data(), 0);
    CHECK(aBack != aData);  // nothing copied before Run
    downloads.Run();
    CHECK(aBack == aData);
    CHECK(bBack == std::vector<uint8_t>(bData.begin() + 333, bData.begin() + 1333));
    CHECK(untouched == std::vector<uint8_t>(4, 0xEE));
    CHECK_THROWS_WITH(downloads.Add(b, bBack.data(), 1000, (1 << 16) - 999), Catch::Contains("outside the buffer"));
    Buffer large(ctx, (size_t(64) << 20) + 4096);
    large.Fill(0x5A5A5A5Au);
    std::vector<uint8_t> largeBack((size_t(64) << 20) + 4096);
    downloads.Add(large, largeBack.data(), largeBack.size());
    downloads.Add(a, aBack.data(), 16);
    downloads.Run();
    CHECK(std::all_of(largeBack.begin(), largeBack.end(), [](uint8_t v) { return v == 0x5A; }));
    CHECK(std::equal(aBack.begin(), aBack.begin() + 16, aData.begin()));
  }

  // Images copy through the same reused staging buffers: a small image, then one larger than any
  // copy before (the buffers grow), then the small one again.
  for (uint32_t side : {7u, 1100u, 7u}) {
    Image img(ctx, side, side, VK_FORMAT_R32_SFLOAT, "staged");
    std::vector<float> texels(size_t(side) * side), texelsBack(texels.size());
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = float(i % 9973) * 0.25f + float(side);
    img.Upload(texels.data(), texels.size() * sizeof(float));
    img.Download(texelsBack.data(), texelsBack.size() * sizeof(float));
    CHECK(texelsBack == texels);
  }
  RequireNoValidationMessages(*ctx);
}

TEST_CASE("SAXPY with push constants and push descriptors", "[runtime]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  const uint32_t n = 1'000'003;  // not a multiple of the group size
  const float a = 1.5f;
  // Dyadic values keep every product and sum exact, so GPU and CPU must agree bit for bit.
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> dist(-(1 << 20), 1 << 20);
  std::vector<float> x(n), y(n);
  for (uint32_t i = 0; i < n; ++i) {
    x[i] = dist(rng) / 256.0f;
    y[i] = dist(rng) / 256.0f;
  }

  auto spirv = CompileGlsl(kSaxpy);
  ComputePipeline pipe(ctx, spirv.data(), spirv.size() * 4, 2, sizeof(SaxpyParams), "saxpy");
  Buffer bx(ctx, n * sizeof(float)), by(ctx, n * sizeof(float));
  bx.Upload(x.data(), n * sizeof(float));
  by.Upload(y.data(), n * sizeof(float));

  VkCommandBuffer cmd = ctx->BeginOneShot();
  pipe.Bind(cmd);
  pipe.PushBuffers(cmd, {bx.View(), by.View()});
  SaxpyParams params{a, n};
  pipe.PushConstants(cmd, &params, sizeof(params));
  uint32_t groups = Dispatch1D(cmd, n, 256);
  ctx->SubmitAndWait(cmd);
  CHECK(groups == GroupCount1D(n, 256));
  CHECK(uint64_t(groups) * 256 >= n);

  std::vector<float> result(n);
  by.Download(result.data(), n * sizeof(float));
  size_t mismatches = 0;
  for (uint32_t i = 0; i < n; ++i) {
    float expected = a * x[i];
    expected += y[i];
    if (result[i] != expected && mismatches++ < 5) UNSCOPED_INFO("i=" << i << " gpu=" << result[i] << " cpu=" << expected);
  }
  REQUIRE(mismatches == 0);
  RequireNoValidationMessages(*ctx);
}

TEST_CASE("Dispatch1D spreads more than 65535 groups over y", "[runtime]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  const uint32_t groupSize = 64;
  const uint64_t threads = 70'000ull * groupSize - 13;  // 70000 groups, last one partial
  REQUIRE(GroupCount1D(threads, groupSize) >= 70'000u);

  auto spirv = CompileGlsl(kCountIds);
  ComputePipeline pipe(ctx, spirv.data(), spirv.size() * 4, 1, 4, "count_ids");
  const size_t slots = threads + 1000;  // room to catch ids past the end
  Buffer counts(ctx, slots * 4);
  counts.Fill(0);

  VkCommandBuffer cmd = ctx->BeginOneShot();
  pipe.Bind(cmd);
  pipe.PushBuffers(cmd, {counts.View()});
  uint32_t n = static_cast<uint32_t>(threads);
  pipe.PushConstants(cmd, &n, 4);
  uint32_t groups = Dispatch1D(cmd, threads, groupSize);
  ctx->SubmitAndWait(cmd);
  CHECK(groups == GroupCount1D(threads, groupSize));
  CHECK(uint64_t(groups) * groupSize >= threads);

  std::vector<uint32_t> result(slots);
  counts.Download(result.data(), slots * 4);
  size_t wrong = 0;
  for (size_t i = 0; i < slots; ++i) {
    uint32_t expected = i < threads ? 1u : 0u;
    if (result[i] != expected && wrong++ < 5) UNSCOPED_INFO("id " << i << " written " << result[i] << " times");
  }
  REQUIRE(wrong == 0);
  RequireNoValidationMessages(*ctx);
}

TEST_CASE("Dispatch helpers compute group counts", "[runtime]") {
  CHECK(GroupCount1D(0, 64) == 0);
  CHECK(GroupCount1D(1, 64) == 1);
  CHECK(GroupCount1D(64, 64) == 1);
  CHECK(GroupCount1D(65, 64) == 2);
  CHECK(GroupCount1D(65535ull * 64, 64) == 65535);
  CHECK(GroupCount1D(70000ull * 64, 64) == 70000);        // 35000 x 2
  CHECK(GroupCount1D(131071ull * 64, 64) >= 131071);      // 3 rows
  CHECK_THROWS_AS(GroupCount1D(10, 0), Error);
}

TEST_CASE("A zero-size Buffer is valid and can be bound", "[runtime]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  Buffer x(ctx, 0), y(ctx, 0);
  CHECK(x.Size() == 0);
  CHECK_FALSE(x.Empty());
  CHECK(x.Handle() != VK_NULL_HANDLE);
  x.Fill(0);
  x.Upload(nullptr, 0);
  x.Download(nullptr, 0);

  auto spirv = CompileGlsl(kSaxpy);
  ComputePipeline pipe(ctx, spirv.data(), spirv.size() * 4, 2, sizeof(SaxpyParams), "saxpy_empty");
  VkCommandBuffer cmd = ctx->BeginOneShot();
  pipe.Bind(cmd);
  pipe.PushBuffers(cmd, {x.View(), y.View()});
  SaxpyParams params{2.0f, 1};  // one thread: the shader touches element 0, inside the padded allocation
  pipe.PushConstants(cmd, &params, sizeof(params));
  Dispatch1D(cmd, 1, 256);
  CHECK(Dispatch1D(cmd, 0, 256) == 0);  // nothing to do is not an error
  ctx->SubmitAndWait(cmd);

  Buffer empty;
  CHECK(empty.Empty());
  CHECK_THROWS_AS(empty.Fill(0), Error);
  RequireNoValidationMessages(*ctx);
}

TEST_CASE("CROSSRT_DEVICE naming no device lists the available ones", "[runtime]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  const std::string defaultDevice = ctx->DeviceName();
  ctx.reset();
  setenv("CROSSRT_DEVICE", "no-such-gpu", 1);
  std::string message;
  try {
    VulkanContext::CreateDefault();
  } catch (const Error& e) {
    message = e.what();
  }
  unsetenv("CROSSRT_DEVICE");
  INFO(message);
  REQUIRE_FALSE(message.empty());
  CHECK(message.find("no-such-gpu") != std::string::npos);
  CHECK(message.find("[0]") != std::string::npos);
  CHECK(message.find(defaultDevice) != std::string::npos);  // every device is listed

  // An index out of range is reported the same way.
  ContextOptions options;
  options.device = "99";
  CHECK_THROWS_AS(VulkanContext::Create(options), Error);
}

TEST_CASE("Device can be chosen by index or name", "[runtime]") {
  auto first = MakeContext();
  if (!first) return;
  // Device 0 by index, then by its name in capitals: the match is a case-insensitive substring.
  ContextOptions options;
  options.validation = true;
  options.device = "0";
  auto byIndex = VulkanContext::Create(options);
  const std::string name = byIndex->DeviceName();
  byIndex.reset();
  std::string upper = name.substr(0, name.find(' '));
  for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
  options.device = upper;
  auto ctx = VulkanContext::Create(options);
  CHECK(ctx->DeviceName() == name);
  CHECK(ctx->hasScalarBlockLayout);
  CHECK(ctx->hasBufferDeviceAddress);
  CHECK(ctx->vkCmdPushDescriptorSetKHR != nullptr);
  Buffer b(ctx, 64);
  CHECK(b.Address() != 0);
  RequireNoValidationMessages(*ctx);
}

TEST_CASE("Device features can be hidden or required (CROSSRT_DEVICE_FEATURES)", "[runtime]") {
  auto first = MakeContext();
  if (!first) return;
  if (const char* env = std::getenv("CROSSRT_DEVICE_FEATURES"); env && *env) {
    WARN("CROSSRT_DEVICE_FEATURES is set, and has the last word on every context: not tested");
    return;
  }
  ContextOptions options;
  options.validation = true;
  options.device = "0";
  options.deviceFeatures = "-ray_query,-ray_tracing_pipeline,-texture_arrays,-float_atomics";
  auto hidden = VulkanContext::Create(options);
  CHECK_FALSE(hidden->hasRayQuery);
  CHECK_FALSE(hidden->hasRayTracingPipeline);
  CHECK_FALSE(hidden->hasTextureArrays);
  CHECK_FALSE(hidden->hasFloatAtomicAdd);
  RequireNoValidationMessages(*hidden);
  hidden.reset();
  // Required: each one the device lacks is refused by name; where it has them all, they are on.
  options.deviceFeatures = "+ray_query,+ray_tracing_pipeline,+texture_arrays";
  ContextOptions plain = options;
  plain.deviceFeatures.clear();
  auto probe = VulkanContext::Create(plain);
  const bool all = probe->hasRayQuery && probe->hasRayTracingPipeline && probe->hasTextureArrays;
  probe.reset();
  if (all) {
    auto required = VulkanContext::Create(options);
    CHECK(required->hasRayQuery);
    CHECK(required->hasRayTracingPipeline);
    CHECK(required->hasTextureArrays);
    RequireNoValidationMessages(*required);
  } else {
    REQUIRE_THROWS_WITH(VulkanContext::Create(options), Catch::Contains("CROSSRT_DEVICE_FEATURES requires"));
  }
  // Words it does not know are refused, naming the ones it knows.
  options.deviceFeatures = "-rayquery";
  REQUIRE_THROWS_WITH(VulkanContext::Create(options), Catch::Contains("ray_query, ray_tracing_pipeline, texture_arrays, float_atomics"));
  options.deviceFeatures = "ray_query";
  REQUIRE_THROWS_WITH(VulkanContext::Create(options), Catch::Contains("is not -name (hide) or +name (require)"));
}

TEST_CASE("GpuTimer measures a dispatch", "[runtime]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  const uint32_t n = 1'000'003;
  auto spirv = CompileGlsl(kSaxpy);
  ComputePipeline pipe(ctx, spirv.data(), spirv.size() * 4, 2, sizeof(SaxpyParams), "saxpy_timed");
  Buffer bx(ctx, n * 4), by(ctx, n * 4);
  bx.Fill(0x3f800000u);  // 1.0f
  by.Fill(0);

  GpuTimer timer(ctx);
  CpuTimer cpu;
  VkCommandBuffer cmd = ctx->BeginOneShot();
  timer.Reset(cmd);
  timer.Begin(cmd, "saxpy");
  pipe.Bind(cmd);
  pipe.PushBuffers(cmd, {bx.View(), by.View()});
  SaxpyParams params{2.0f, n};
  pipe.PushConstants(cmd, &params, sizeof(params));
  Dispatch1D(cmd, n, 256);
  timer.End(cmd, "saxpy");
  ctx->SubmitAndWait(cmd);
  timer.Collect();

  CHECK(timer.LastMs("saxpy") > 0.0f);
  CHECK(timer.LastMs("saxpy") <= cpu.ElapsedMs() + 1.0f);
  CHECK(timer.LastMs("unknown") == 0.0f);
  RequireNoValidationMessages(*ctx);
}

TEST_CASE("EnsureSize reallocates only when growing", "[runtime]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  Buffer b;
  EnsureSize(ctx, b, 100);
  REQUIRE_FALSE(b.Empty());
  CHECK(b.Size() == 100);
  VkBuffer first = b.Handle();
  EnsureSize(ctx, b, 50);
  CHECK(b.Handle() == first);
  CHECK(b.Size() == 100);
  EnsureSize(ctx, b, 100);
  CHECK(b.Handle() == first);
  EnsureSize(ctx, b, 1000);  // the new buffer exists before the old one is freed, so handles differ
  CHECK(b.Handle() != first);
  CHECK(b.Size() == 1000);
  RequireNoValidationMessages(*ctx);
}

TEST_CASE("The pipeline cache is saved when the context is destroyed", "[runtime]") {
  const fs::path dir = TempDir() / "pipeline_cache_test";
  fs::remove_all(dir);
  const char* previous = std::getenv("CROSSRT_PIPELINE_CACHE_DIR");
  const std::string saved = previous ? previous : "";
  setenv("CROSSRT_PIPELINE_CACHE_DIR", dir.string().c_str(), 1);

  auto spirv = CompileGlsl(kSaxpy);
  for (int round = 0; round < 2; ++round) {  // the second round loads what the first saved
    ContextOptions options;
    options.validation = true;
    std::shared_ptr<VulkanContext> ctx;
    try {
      ctx = VulkanContext::Create(options);
    } catch (const NoDeviceError& e) {
      WARN("skipped, no Vulkan device: " << e.what());
      return;
    }
    {
      ComputePipeline pipe(ctx, spirv.data(), spirv.size() * 4, 2, sizeof(SaxpyParams), "saxpy_cached");
    }
    RequireNoValidationMessages(*ctx);
    ctx.reset();

    size_t files = 0;
    for (const auto& entry : fs::directory_iterator(dir)) {
      INFO(entry.path().string());
      CHECK(entry.path().filename().string().find("pipeline_cache_") == 0);
      CHECK(fs::file_size(entry.path()) > 0);
      ++files;
    }
    CHECK(files == 1);
  }

  if (previous)
    setenv("CROSSRT_PIPELINE_CACHE_DIR", saved.c_str(), 1);
  else
    unsetenv("CROSSRT_PIPELINE_CACHE_DIR");
}

// Rays straight down (-z) at given x, y from z = 5; the shader writes t, primitive index, instance
// index and custom index of the committed hit (t = -1 and ids ~0u for a miss).
static const char* kRayQueryProbe = R"(#version 460
#extension GL_EXT_ray_query : require
layout(local_size_x = 64) in;
layout(binding = 0) readonly buffer Rays { vec2 xy[]; };
layout(binding = 1) buffer Hits { vec4 hits[]; };
layout(binding = 2) uniform accelerationStructureEXT scene;
layout(push_constant) uniform Args { uint n; };
void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= n) return;
  rayQueryEXT q;
  rayQueryInitializeEXT(q, scene, gl_RayFlagsOpaqueEXT, 0xFF, vec3(xy[i], 5.0), 0.0, vec3(0.0, 0.0, -1.0), 100.0);
  while (rayQueryProceedEXT(q)) {}
  if (rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionNoneEXT)
    hits[i] = vec4(-1.0, uintBitsToFloat(~0u), uintBitsToFloat(~0u), uintBitsToFloat(~0u));
  else
    hits[i] = vec4(rayQueryGetIntersectionTEXT(q, true), uintBitsToFloat(uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true))),
                   uintBitsToFloat(uint(rayQueryGetIntersectionInstanceIdEXT(q, true))),
                   uintBitsToFloat(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true))));
}
)";

TEST_CASE("RayTracingScene: instances of meshes traced with ray queries, or a clear error without them", "[runtime][device-features]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  if (!ctx->hasRayQuery) {
    INFO(ctx->DeviceName() << " has no ray queries: only the error is checked");
    if (!ctx->hasRayTracingPipeline) REQUIRE_THROWS_WITH(RayTracingScene(ctx), Catch::Contains("has no acceleration structures"));
    return;
  }
  // Mesh 0: two triangles covering [0,1]^2 at z = 0; mesh 1: empty; mesh 2: one triangle at z = 1.
  const std::vector<float> square = {0, 0, 0, 1, 0, 0, 1, 1, 0, /**/ 0, 0, 0, 1, 1, 0, 0, 1, 0};
  const std::vector<float> single = {0, 0, 1, 1, 0, 1, 0, 1, 1};
  std::vector<RayTracingScene::Mesh> meshes = {{square.data(), 2}, {nullptr, 0}, {single.data(), 1}};
  auto placed = [](uint32_t mesh, float dx) {
    RayTracingScene::Instance in;
    in.mesh = mesh;
    const float rows[12] = {1, 0, 0, dx, 0, 1, 0, 0, 0, 0, 1, 0};
    std::memcpy(in.toWorldRows, rows, sizeof(rows));
    return in;
  };
  // Instance 0: the square; 1: the empty mesh (never hit); 2: the single triangle moved to x + 10.
  std::vector<RayTracingScene::Instance> instances = {placed(0, 0.0f), placed(1, 0.0f), placed(2, 10.0f)};
  RayTracingScene scene(ctx);
  scene.Build(meshes, instances);
  REQUIRE_FALSE(scene.Empty());

  const std::vector<float> xy = {0.75f, 0.25f, /**/ 0.25f, 0.75f, /**/ 10.25f, 0.25f, /**/ 5.0f, 5.0f};
  const uint32_t n = 4;
  Buffer rays(ctx, sizeof(float) * xy.size()), hits(ctx, sizeof(float) * 4 * n);
  rays.Upload(xy.data(), sizeof(float) * xy.size());
  auto spirv = CompileGlsl(kRayQueryProbe);
  ComputePipeline pipe(ctx, spirv.data(), spirv.size() * 4,
                       {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR},
                       sizeof(uint32_t), "ray_query_probe");
  VkCommandBuffer cmd = ctx->BeginOneShot();
  pipe.Bind(cmd);
  pipe.PushBindings(cmd, {rays.View(), hits.View(), Binding::SceneOf(scene)});
  pipe.PushConstants(cmd, &n, sizeof(n));
  Dispatch1D(cmd, n, 64);
  ctx->SubmitAndWait(cmd);
  std::vector<float> out(4 * n);
  hits.Download(out.data(), sizeof(float) * out.size());
  auto id = [&](size_t i) {
    uint32_t u;
    std::memcpy(&u, &out[i], 4);
    return u;
  };
  CHECK(out[0] == Approx(5.0f));  // the square's first triangle
  CHECK(id(1) == 0u);
  CHECK(id(2) == 0u);
  CHECK(id(3) == 0u);
  CHECK(id(5) == 1u);  // its second triangle
  CHECK(out[8] == Approx(4.0f));  // the moved triangle at z = 1
  CHECK(id(9) == 0u);
  CHECK(id(10) == 2u);  // instance index = position among the instances, the empty one counted
  CHECK(id(11) == 2u);  // custom index = mesh
  CHECK(out[12] == -1.0f);  // nothing at (5, 5)
  RequireNoValidationMessages(*ctx);

  scene.Build({}, {});  // an empty scene: a top level every ray misses
  REQUIRE_FALSE(scene.Empty());
}

// A ray generation shader executing one of two callable shaders per thread (the shape of level-3
// virtual calls), in rows of the launch as generated 1D kernels use.
const char* kCallableProbeRayGen = R"(#version 460
#extension GL_EXT_ray_tracing : require
layout(std430, binding = 0) buffer Out { uint values[]; };
layout(push_constant) uniform Args { uint count; };
struct Call { uint argument; uint result; };
layout(location = 0) callableDataEXT Call call;
void main() {
  const uint i = gl_LaunchIDEXT.x + gl_LaunchIDEXT.y * gl_LaunchSizeEXT.x;
  if (i >= count) return;
  call.argument = i;
  executeCallableEXT(i % 2u, 0);
  values[i] = call.result;
}
)";
const char* kCallableDouble = R"(#version 460
#extension GL_EXT_ray_tracing : require
struct Call { uint argument; uint result; };
layout(location = 0) callableDataInEXT Call call;
void main() { call.result = call.argument * 2u; }
)";
const char* kCallableOffset = R"(#version 460
#extension GL_EXT_ray_tracing : require
struct Call { uint argument; uint result; };
layout(location = 0) callableDataInEXT Call call;
void main() { call.result = call.argument + 1000u; }
)";

TEST_CASE("RayTracingPipeline: callable shaders chosen per thread, or a clear error without ray tracing pipelines", "[runtime][device-features]") {
  auto ctx = MakeContext();
  if (!ctx) return;
  const auto rayGen = CompileGlsl(kCallableProbeRayGen, "rgen");
  const auto doubled = CompileGlsl(kCallableDouble, "rcall"), offset = CompileGlsl(kCallableOffset, "rcall");
  auto create = [&] {
    RayTracingShaders shaders;
    shaders.rayGeneration = {rayGen.data(), rayGen.size() * 4};
    shaders.callables = {{doubled.data(), doubled.size() * 4}, {offset.data(), offset.size() * 4}};
    return RayTracingPipeline(ctx, shaders, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, sizeof(uint32_t), "callable_probe");
  };
  if (!ctx->hasRayTracingPipeline) {
    INFO(ctx->DeviceName() << " has no ray tracing pipelines: only the error is checked");
    REQUIRE_THROWS_WITH(create(), Catch::Contains("has no ray tracing pipelines"));
    RequireNoValidationMessages(*ctx);
    return;
  }
  RayTracingPipeline pipe = create();
  const uint32_t n = 70001;  // more than one row of 65536
  Buffer out(ctx, n * sizeof(uint32_t));
  out.Fill(0xffffffffu);
  VkCommandBuffer cmd = ctx->BeginOneShot();
  pipe.Bind(cmd);
  pipe.PushBuffers(cmd, {out.View()});
  pipe.PushConstants(cmd, &n, sizeof(n));
  pipe.TraceCmd(cmd, std::min<uint32_t>(n, 65536u), (n + 65535u) / 65536u, 1);
  ctx->SubmitAndWait(cmd);
  std::vector<uint32_t> values(n);
  out.Download(values.data(), n * sizeof(uint32_t));
  size_t wrong = 0;
  for (uint32_t i = 0; i < n; ++i)
    if (values[i] != (i % 2 == 0 ? 2 * i : i + 1000) && wrong++ < 5) UNSCOPED_INFO("i=" << i << " got " << values[i]);
  REQUIRE(wrong == 0);
  RequireNoValidationMessages(*ctx);
}

// Leaves in a ray tracing pipeline: a grid of side x side cells, most holding a box (some flat
// along z), each box an instance of class (x + y) % 2 whose intersection shader reports
// 2 * instance + class; one ray per cell, down through its centre.
const char* kLeafProbeRayGen = R"(#version 460
#extension GL_EXT_ray_tracing : require
layout(std430, binding = 0) buffer Out { uint values[]; };
layout(binding = 1) uniform accelerationStructureEXT leaves;
layout(push_constant) uniform Args { uint side; };
layout(location = 0) rayPayloadEXT uint hit;
void main() {
  const uint x = gl_LaunchIDEXT.x, y = gl_LaunchIDEXT.y;
  hit = 0xFFFFFFFFu;
  traceRayEXT(leaves, gl_RayFlagsNoneEXT, 0xFF, 0, 0, 0, vec3(x + 0.5, y + 0.5, 10.0), 0.0, vec3(0.0, 0.0, -1.0), 100.0, 0);
  values[y * side + x] = hit;
}
)";
const char* kLeafProbeMiss = R"(#version 460
#extension GL_EXT_ray_tracing : require
void main() {}
)";
const char* kLeafProbeHit = R"(#version 460
#extension GL_EXT_ray_tracing : require
hitAttributeEXT uint reported;
layout(location = 0) rayPayloadInEXT uint hit;
void main() { hit = reported; }
)";
std::string LeafProbeIntersection(unsigned cls) {
  return "#version 460\n#extension GL_EXT_ray_tracing : require\nhitAttributeEXT uint reported;\n"
         "void main() { reported = 2u * uint(gl_InstanceID) + " + std::to_string(cls) + "u; reportIntersectionEXT(5.0, 0u); }\n";
}

TEST_CASE("RayTracingScene leaves: a box per instance, in order, each class's intersection shader, or a clear error", "[runtime][device-features]") {
  // Boxes are checked before anything is built, on every device.
  std::vector<RayTracingScene::LeafBox> bad = {{{0, 0, 0}, {1, 1, 1}, 0}, {{0, 2, 0}, {1, 1, 1}, 0}};
  REQUIRE_THROWS_WITH(RayTracingScene::CheckLeafBoxes(bad, "probe"), Catch::Contains("probe[1]") && Catch::Contains("min <= max (axis 1"));
  bad[1].max[1] = std::nanf("");
  REQUIRE_THROWS_WITH(RayTracingScene::CheckLeafBoxes(bad, "probe"), Catch::Contains("probe[1]"));
  auto ctx = MakeContext();
  if (!ctx) return;
  const auto rayGen = CompileGlsl(kLeafProbeRayGen, "rgen"), miss = CompileGlsl(kLeafProbeMiss, "rmiss"), hit = CompileGlsl(kLeafProbeHit, "rchit");
  const auto isect0 = CompileGlsl(LeafProbeIntersection(0).c_str(), "rint"), isect1 = CompileGlsl(LeafProbeIntersection(1).c_str(), "rint");
  auto create = [&] {
    RayTracingShaders shaders;
    shaders.rayGeneration = {rayGen.data(), rayGen.size() * 4};
    shaders.misses = {{miss.data(), miss.size() * 4}};
    shaders.hitGroups = {{{isect0.data(), isect0.size() * 4}, {hit.data(), hit.size() * 4}}, {{isect1.data(), isect1.size() * 4}, {hit.data(), hit.size() * 4}}};
    return RayTracingPipeline(ctx, shaders, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR}, sizeof(uint32_t), "leaf_probe");
  };
  if (!ctx->hasRayTracingPipeline) {
    INFO(ctx->DeviceName() << " has no ray tracing pipelines: only the errors are checked");
    REQUIRE_THROWS_WITH(create(), Catch::Contains("has no ray tracing pipelines"));
    RequireNoValidationMessages(*ctx);
    return;
  }
  RayTracingPipeline pipe = create();
  RayTracingScene scene(ctx);
  const uint32_t side = 37;
  std::vector<RayTracingScene::LeafBox> leaves;
  std::vector<uint32_t> expected(side * side, 0xFFFFFFFFu);
  for (uint32_t y = 0; y < side; ++y)
    for (uint32_t x = 0; x < side; ++x) {
      if ((x + 2 * y) % 7 == 3) continue;  // an empty cell: the ray misses
      const float top = x % 3 == 0 ? 0.5f : 1.0f;  // every third box is flat along z
      const uint32_t cls = (x + y) % 2;
      expected[y * side + x] = 2 * uint32_t(leaves.size()) + cls;
      leaves.push_back({{float(x), float(y), 0.5f * (x % 3 == 0)}, {float(x + 1), float(y + 1), top}, cls});
    }
  Buffer out(ctx, side * side * sizeof(uint32_t));
  auto trace = [&] {
    out.Fill(0u);
    VkCommandBuffer cmd = ctx->BeginOneShot();
    pipe.Bind(cmd);
    pipe.PushBindings(cmd, {out.View(), Binding::SceneOf(scene)});
    pipe.PushConstants(cmd, &side, sizeof(side));
    pipe.TraceCmd(cmd, side, side, 1);
    ctx->SubmitAndWait(cmd);
    std::vector<uint32_t> values(side * side);
    out.Download(values.data(), values.size() * sizeof(uint32_t));
    return values;
  };
  scene.BuildLeaves(leaves, "probe");
  std::vector<uint32_t> values = trace();
  size_t wrong = 0;
  for (size_t i = 0; i < values.size(); ++i)
    if (values[i] != expected[i] && wrong++ < 5) UNSCOPED_INFO("cell " << i << " got " << values[i] << ", expected " << expected[i]);
  REQUIRE(wrong == 0);
  scene.BuildLeaves({}, "probe");  // no leaves: every ray misses
  values = trace();
  REQUIRE(std::count(values.begin(), values.end(), 0xFFFFFFFFu) == long(values.size()));
  RequireNoValidationMessages(*ctx);
}

// The CPU backend's radix sort takes one to three passes of 11 bits, skipping a pass whose digit
// never varies; an odd number of passes leaves the result in its scratch copy, which it copies
// back. Each key range below takes a different number of passes, on one thread (5,000 records)
// and on all (65,536); below 4,096 records (1,000) it sorts (key, place) pairs instead.
TEST_CASE("CPU radix sort: stable for keys that need 0, 1, 2 and 3 passes, small and large", "[runtime][sort]")
{
  std::mt19937 rng(5);
  for (uint32_t keyMask : {0x0u, 0x7FFu, 0x3FFFFFu, 0xFFFFFFFFu})
    for (size_t n : {size_t(1000), size_t(5000), size_t(1) << 16})
    {
      INFO("key mask " << keyMask << ", n " << n);
      std::vector<uint32_t> records(2 * n);  // (key, original index)
      for (size_t i = 0; i < n; ++i) records[2 * i] = rng() & keyMask, records[2 * i + 1] = uint32_t(i);
      std::vector<std::pair<uint32_t, uint32_t>> expected;
      for (size_t i = 0; i < n; ++i) expected.emplace_back(records[2 * i], records[2 * i + 1]);
      std::stable_sort(expected.begin(), expected.end(), [](auto a, auto b) { return a.first < b.first; });
      crossrt::SortKey key;
      key.strideWords = 2;
      crossrt::RadixSortWords(records.data(), n, key);
      size_t wrong = 0;
      for (size_t i = 0; i < n; ++i) wrong += records[2 * i] != expected[i].first || records[2 * i + 1] != expected[i].second;
      REQUIRE(wrong == 0);
    }
}

// crossrt::ParallelFor (CpuLoops.h), the generated loops' runner: every iteration once, from any
// first value and of any integer type, on all cores or on this thread; loops inside a chunk, and a
// loop of another thread while the pool is busy, run on their thread; a chunk's exception reaches
// the caller and leaves the pool working; chunks' parts of reductions add up to the whole.
TEST_CASE("ParallelFor runs every iteration once, on the pool's threads and the caller's", "[runtime][parallel]")
{
  auto coverage = [](auto begin, auto end, long long grain, bool parallel) {
    using T = decltype(begin);
    std::vector<std::atomic<int>> seen(begin < end ? size_t(end - begin) + 1 : 1);
    std::atomic<int> outside{0};
    crossrt::ParallelFor<T>(parallel, begin, end, grain, [&](T first, T last) {
      for (T i = first; i < last; i++) {
        if (i < begin || i >= end) ++outside;
        else ++seen[size_t(i - begin)];
      }
    });
    int wrong = outside.load();
    for (size_t i = 0; i + 1 < seen.size(); ++i) wrong += seen[i].load() != 1;
    return wrong;
  };
  for (bool parallel : {true, false}) {
    CHECK(coverage(0, 10000, 1024, parallel) == 0);
    CHECK(coverage(-37, 1001, 16, parallel) == 0);
    CHECK(coverage(5, 6, 1, parallel) == 0);
    CHECK(coverage(uint32_t(3), uint32_t(4099), 7, parallel) == 0);
    CHECK(coverage(size_t(0), size_t(333), 1000, parallel) == 0);
  }
  CHECK(coverage(10, 10, 16, true) == 0);  // empty
  CHECK(coverage(10, 3, 16, true) == 0);   // empty, end before begin

  if (crossrt::LoopThreads() > 1) {
    // Chunks long enough for a worker to wake and take some.
    std::mutex m;
    std::set<std::thread::id> threads;
    crossrt::ParallelFor<int>(true, 0, 64, 1, [&](int, int) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      const std::lock_guard<std::mutex> lock(m);
      threads.insert(std::this_thread::get_id());
    });
    CHECK(threads.size() > 1);
  }

  // A loop inside a chunk runs on the chunk's thread. (With one thread, OMP_NUM_THREADS=1, there is
  // no pool: the outer loop is one chunk on this thread, not inside a parallel loop.)
  std::atomic<int> innerOnOtherThreads{0}, inner{0};
  crossrt::ParallelFor<int>(true, 0, 8, 1, [&](int outerFirst, int outerLast) {
    const auto self = std::this_thread::get_id();
    CHECK(crossrt::InParallelLoop() == (crossrt::LoopThreads() > 1));
    for (int outer = outerFirst; outer < outerLast; ++outer)
      crossrt::ParallelFor<int>(true, 0, 100, 1, [&](int first, int last) {
        inner += last - first;
        if (std::this_thread::get_id() != self) ++innerOnOtherThreads;
      });
  });
  CHECK(inner.load() == 800);
  CHECK(innerOnOtherThreads.load() == 0);
  CHECK_FALSE(crossrt::InParallelLoop());

  // Another thread's loop, while this one holds the pool, runs whole on that thread.
  std::atomic<int> otherCount{0};
  std::atomic<bool> otherDone{false};
  crossrt::ParallelFor<int>(true, 0, 2, 1, [&](int first, int) {
    if (first != 0) return;
    std::thread other([&] {
      crossrt::ParallelFor<int>(true, 0, 1000, 10, [&](int f, int l) { otherCount += l - f; });
      otherDone = true;
    });
    other.join();
  });
  CHECK(otherDone.load());
  CHECK(otherCount.load() == 1000);

  // An exception in a chunk reaches the caller after the other chunks; the pool keeps working.
  std::atomic<int> ran{0};
  CHECK_THROWS_WITH(crossrt::ParallelFor<int>(true, 0, 100, 1,
                                              [&](int first, int last) {
                                                ran += last - first;
                                                if (first <= 50 && 50 < last) throw std::runtime_error("iteration 50");
                                              }),
                    "iteration 50");
  CHECK(ran.load() == 100);
  CHECK(coverage(0, 5000, 64, true) == 0);
}

// Many short loops back to back, from three threads at once, some with loops inside their chunks:
// workers that wake late for one loop must never run a chunk of the next one twice or skip one.
TEST_CASE("ParallelFor under stress: loops back to back from several threads", "[runtime][parallel]")
{
  std::atomic<int> wrong{0};
  auto loops = [&](unsigned seed) {
    std::mt19937 rng(seed);
    for (int loop = 0; loop < 400; ++loop) {
      const int n = int(rng() % 3000);
      const long long grain = 1 + rng() % 64;
      const bool nested = rng() % 8 == 0;
      std::vector<std::atomic<int>> seen(size_t(n) + 1);
      crossrt::ParallelFor<int>(true, 0, n, grain, [&](int first, int last) {
        for (int i = first; i < last; i++) {
          if (nested) {
            std::atomic<int> inner{0};
            crossrt::ParallelFor<int>(true, 0, 3, 1, [&](int f, int l) { inner += l - f; });
            if (inner.load() != 3) ++wrong;
          }
          ++seen[size_t(i)];
        }
      });
      for (int i = 0; i < n; ++i) wrong += seen[size_t(i)].load() != 1;
    }
  };
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < 3; ++t) threads.emplace_back(loops, 1000 + t);
  for (auto& t : threads) t.join();
  CHECK(wrong.load() == 0);
}

TEST_CASE("LoopReductions: chunks' parts of sums, minima and arrays add up to the whole", "[runtime][parallel]")
{
  const int n = 100000;
  long long sumTotal = 7;  // the total before the loop counts too
  float minTotal = 1.0e30f;
  int histogramTotal[4] = {1, 1, 1, 1};
  crossrt::LoopReductions reductions;
  crossrt::ParallelFor<int>(true, 0, n, 1024, [&](int first, int last) {
    long long sum;
    reductions.StartFromZero(sum);
    float lowest;
    reductions.StartFromTotal(lowest, minTotal);
    int histogram[4];
    reductions.StartFromZero(histogram);
    for (int i = first; i < last; i++) {
      sum += i;
      lowest = std::min(lowest, float((i * 7919) % n) - 5.0f);
      histogram[i % 4] += 1;
    }
    reductions.Merge(sumTotal, sum, crossrt::Sum());
    reductions.Merge(minTotal, lowest, crossrt::Minimum());
    reductions.Merge(histogramTotal, histogram, crossrt::Sum());
  });
  CHECK(sumTotal == 7 + (long long)n * (n - 1) / 2);
  CHECK(minTotal == -5.0f);
  for (int h : histogramTotal) CHECK(h == 1 + n / 4);
}

// The generated _ISPC classes take each kernel's function through IspcPick: the version of the
// widest target this CPU runs, not ISPC's dispatch function (whose first call asks the CPU with
// CPUID, 27 us in a virtual machine), or the one CROSSRT_ISPC_TARGET names.
TEST_CASE("IspcPick takes the widest ISPC target this CPU runs, or the one CROSSRT_ISPC_TARGET names", "[runtime]")
{
  using Fn = int (*)();
  const Fn dispatch = [] { return -1; };
  const std::initializer_list<Fn> perTarget = {[] { return 0; }, [] { return 1; }, [] { return 2; }};
  int expected = -1;
  const char* forced = std::getenv("CROSSRT_ISPC_TARGET");
  for (int i = 0; i < int(std::size(crossrt::kIspcTargets)); ++i)
    if (forced && *forced && std::string(forced) != "auto" ? forced == std::string(crossrt::kIspcTargets[i]) : crossrt::CpuRunsIspcTarget(i))
      expected = i;
  REQUIRE(expected >= 0);  // every x86-64 CPU these tests run on has SSE4.2
  CHECK(crossrt::IspcPick(dispatch, perTarget)() == expected);
  CHECK(crossrt::IspcTargetInUse() == crossrt::kIspcTargets[expected]);  // what LaneMemory names the machine by
}

// crossrt::ParallelChoice, with the times given: the way that measured faster is taken (a try that
// wins is made twice before it is believed), the other is tried again after 16 calls, then 64..., a loop whose parallel run takes longer than a time
// slice always runs on all cores, loops of sizes 4x apart choose apart, and a loop of one
// iteration never does.
TEST_CASE("ParallelChoice takes the faster way and tries the other now and then", "[runtime][parallel]")
{
  if (crossrt::ParallelChoice::AlwaysAllCores()) {  // CROSSRT_CPU_PARALLEL=always: no choice to test, every loop on all cores
    crossrt::ParallelChoice choice;
    for (int i = 0; i < 20; ++i) {
      REQUIRE(choice.Choose(1000) == (omp_get_max_threads() > 1));
      choice.Record(true, 1000, 8.0);
    }
    return;
  }
  const int threadsBefore = omp_get_max_threads();
  omp_set_num_threads(2);
  auto count = [](crossrt::ParallelChoice& choice, int calls, double parallelMs, double serialMs, long long iterations = 1000) {
    int parallel = 0;
    for (int i = 0; i < calls; ++i) {
      const bool p = choice.Choose(iterations);
      choice.Record(p, iterations, p ? parallelMs : serialMs);
      parallel += p;
    }
    return parallel;
  };
  SECTION("short loops: the measured times decide") {
    crossrt::ParallelChoice choice;
    choice.AssumeOthersRunnable(0);
    REQUIRE(choice.Choose(1000));  // first the way the loop is written for
    choice.Record(true, 1000, 1.0);
    REQUIRE_FALSE(choice.Choose(1000));  // then one run on this thread, cheap (1 ms)
    choice.Record(false, 1000, 0.5);
    REQUIRE(choice.Mean(false, 1000) < 0.0f);  // faster once: not believed yet
    REQUIRE_FALSE(choice.Choose(1000));  // so tried again
    choice.Record(false, 1000, 0.5);
    REQUIRE(choice.Mean(false, 1000) == Approx(0.0005f));
    // One core wins: of the next 16 calls, one tries all cores again; after that try lost, 64
    // calls pass before the next.
    CHECK(count(choice, 16, 1.0, 0.5) == 1);
    CHECK(count(choice, 63, 1.0, 0.5) == 0);
    CHECK(count(choice, 1, 1.0, 0.5) == 1);
    // The load goes away: all cores become faster. Tried after 256 calls (and again on the next,
    // to believe it), they win, and keep winning but for the tries of one core (after 16 calls, then 64).
    CHECK(count(choice, 256, 0.1, 0.5) == 1);
    CHECK(count(choice, 64, 0.1, 0.5) == 63);
  }
  SECTION("on a quiet machine, a loop longer than a time slice always runs on all cores") {
    crossrt::ParallelChoice choice;
    choice.AssumeOthersRunnable(0);
    CHECK(count(choice, 100, 8.0, 4.0) == 100);
    CHECK(count(choice, 100, 30.0, 4.0) == 100);
    CHECK(choice.Mean(false, 1000) < 0.0f);  // never tried on one core
  }
  SECTION("beside other runnable threads, a loop's slowed parallel runs do not hold back its first try of one core") {
    crossrt::ParallelChoice choice;
    choice.AssumeOthersRunnable(3);
    CHECK(count(choice, 3, 8.0, 6.0) == 1);  // all cores (two time slices), then one core twice (faster: tried again)
    CHECK(choice.Mean(false, 1000) == Approx(0.006f));
    CHECK(count(choice, 20, 8.0, 6.0) == 1);  // one core wins; all cores tried once in 16 calls
    // The load goes: all cores win their next try (after 64 calls, the 60th here) and the one after. One core, 6 ms
    // of work of which the other thread saves 3, under a time slice, is tried again 16 calls later.
    CHECK(count(choice, 64, 1.0, 6.0) == 5);
    // Quiet, the same first parallel run gets no try: its other thread saves 8 ms.
    crossrt::ParallelChoice quiet;
    quiet.AssumeOthersRunnable(0);
    CHECK(count(quiet, 20, 8.0, 6.0) == 20);
    // 15 ms of work on one core, of which the other thread would save 7.5: tried (twice, to believe
    // it), then all cores even though one core measured faster.
    crossrt::ParallelChoice longer;
    longer.AssumeOthersRunnable(1);
    CHECK(count(longer, 20, 20.0, 15.0) == 18);
    // A loop whose parallel runs took over 40 ms is never tried on one core, loaded or not.
    crossrt::ParallelChoice longLoop;
    longLoop.AssumeOthersRunnable(3);
    CHECK(count(longLoop, 50, 60.0, 100.0) == 50);
    CHECK(longLoop.Mean(false, 1000) < 0.0f);
  }
  SECTION("each size class has its own choice") {
    crossrt::ParallelChoice choice;
    choice.AssumeOthersRunnable(0);
    // Small loops: starting the threads costs more than the loop, one core wins.
    CHECK(count(choice, 2, 1.0, 0.5) == 1);
    CHECK(count(choice, 10, 1.0, 0.5) == 0);
    // Loops 100x as long, where all cores take a fifth of one core's time: all cores from their
    // first call (measured with the small loops, one core's time per iteration was the lower).
    CHECK(count(choice, 20, 10.0, 50.0, 100000) == 20);
    CHECK(choice.Mean(false, 100000) < 0.0f);
    CHECK(choice.Mean(true, 100000) == Approx(0.0001f));
    // Small again: one core, as before.
    CHECK(count(choice, 5, 1.0, 0.5) == 0);
    CHECK(crossrt::LoopSizeClass(1100) == crossrt::LoopSizeClass(4000));  // [4^5, 4^6)
  }
  SECTION("nothing to share") {
    crossrt::ParallelChoice choice;
    CHECK_FALSE(choice.Choose(1));
    CHECK_FALSE(choice.Choose(0));
  }
  omp_set_num_threads(threadsBefore);
}

// crossrt::LaneChoice, with the times given: an _ISPC kernel runs in SIMD lanes on its first two
// calls (the first not counted), tries its scalar loop on the third (and the fourth, where it was
// faster: a way that wins once is tried again before it is believed; where the work grows and the
// faster way's mean passes the other's old one, the other is tried, not taken), then takes the faster way and
// tries the other after 16 calls, then 64... while it loses, on the cores the verdict's last run
// ran on; sizes a factor of 4 apart are chosen apart; a call that ran no loop counts for nothing.
TEST_CASE("LaneChoice runs a kernel in lanes or as a scalar loop, whichever has been faster", "[runtime][parallel]")
{
  if (const char* forced = std::getenv("CROSSRT_ISPC_LANES"); forced && std::string(forced) == "never")
    REQUIRE(crossrt::LaneChoice::LanesMode() == crossrt::LaneChoice::Mode::Never);
  if (crossrt::LaneChoice::LanesMode() != crossrt::LaneChoice::Mode::Measure) {
    // CROSSRT_ISPC_LANES=always or never (ispc_lanes_never.equivalence runs this case so): every
    // call takes that way, whatever was measured.
    const bool always = crossrt::LaneChoice::LanesMode() == crossrt::LaneChoice::Mode::Always;
    crossrt::LaneChoice choice;
    for (int i = 0; i < 20; ++i) {
      REQUIRE(choice.Choose() == always);
      choice.Record(always, 1000, always ? 3.0 : 1.0);
    }
    CHECK(choice.Mean(0) < 0.0f);  // nothing measured
    return;
  }
  auto count = [](crossrt::LaneChoice& choice, int calls, double lanesMs, double scalarMs, long long iterations = 1000) {
    int lanes = 0;
    for (int i = 0; i < calls; ++i) {
      const bool l = choice.Choose();
      choice.Record(l, iterations, l ? lanesMs : scalarMs);
      lanes += l;
    }
    return lanes;
  };
  SECTION("the scalar loop wins on this CPU") {
    crossrt::LaneChoice choice;
    REQUIRE(choice.Choose());
    choice.Record(true, 1000, 50.0);  // the first call: memory touched, not counted
    CHECK(choice.Mean(1) < 0.0f);
    REQUIRE(choice.Choose());
    choice.Record(true, 1000, 3.0);
    CHECK(choice.Mean(1) == Approx(0.003f));
    REQUIRE_FALSE(choice.Choose());  // the scalar loop
    choice.Record(false, 1000, 1.0);
    CHECK(choice.Mean(0) < 0.0f);    // faster once: not believed yet
    REQUIRE_FALSE(choice.Choose());  // so tried again
    choice.Record(false, 1000, 1.4);
    CHECK(choice.Mean(0) == Approx(0.0012f));  // the mean of both tries
    CHECK(count(choice, 16, 3.0, 1.0) == 1);  // lanes tried once in 16 calls, and lost
    CHECK(count(choice, 63, 3.0, 1.0) == 0);
    CHECK(count(choice, 1, 3.0, 1.0) == 1);
  }
  SECTION("lanes win: the scalar loop, having lost, is tried again after 64 calls") {
    crossrt::LaneChoice choice;
    CHECK(count(choice, 2, 1.0, 3.0) == 2);
    CHECK(count(choice, 1, 1.0, 3.0) == 0);
    CHECK(count(choice, 16, 1.0, 3.0) == 16);
    CHECK(count(choice, 64, 1.0, 3.0) == 63);
    CHECK(choice.Mean(0) == Approx(0.003f));
  }
  SECTION("where the work grows, the lanes' mean passing the scalar loop's old one makes the next call a try, not a switch") {
    crossrt::LaneChoice choice;
    CHECK(count(choice, 3, 1.0, 3.0) == 2);  // lanes, then the scalar loop's try: 3 ms, it lost
    // Ten times the work (a larger mesh): lanes take 10 ms, the scalar loop 30. Its mean, 0.003 ms
    // per iteration from the small work, is soon below the lanes' mean.
    int scalarRuns = 0, tries = 0;
    for (int i = 0; i < 30; ++i) {
      bool trying = false;
      const bool lanes = choice.Choose(trying);
      scalarRuns += !lanes;
      tries += !lanes && trying;
      choice.Record(lanes, 1000, lanes ? 10.0 : 30.0);
    }
    CHECK(scalarRuns == 1);  // measured again, once, and it lost
    CHECK(tries == 1);
    CHECK(choice.Mean(0) == Approx(0.03f));
  }
  SECTION("one fast call of the other way does not switch: the next call tries it again, and the mean of both decides") {
    crossrt::LaneChoice choice;
    CHECK(count(choice, 2, 1.0, 3.0) == 2);
    REQUIRE_FALSE(choice.Choose());
    choice.Record(false, 1000, 0.5);  // the scalar loop, once faster (noise)
    REQUIRE_FALSE(choice.Choose());
    choice.Record(false, 1000, 3.0);  // and then not
    CHECK(choice.Mean(0) == Approx(0.00175f));
    CHECK(count(choice, 64, 1.0, 3.0) == 63);  // lanes, the scalar loop tried again after 64 calls
    // Later the lanes slow down (the machine got loaded), and the scalar loop, tried after 256
    // calls, wins twice in a row: it becomes the verdict.
    CHECK(count(choice, 255, 3.0, 0.5) == 255);
    CHECK(count(choice, 2, 3.0, 0.5) == 0);
    CHECK(count(choice, 15, 3.0, 0.5) == 0);
    CHECK(count(choice, 1, 3.0, 0.5) == 1);  // lanes tried after 16 calls
  }
  SECTION("each size class has its own choice") {
    crossrt::LaneChoice choice;
    CHECK(count(choice, 3, 3.0, 1.0) == 2);  // small loops: the scalar loop wins
    CHECK(count(choice, 10, 3.0, 1.0) == 0);
    // Large loops (100x the iterations): lanes win there. The first large call still runs as the
    // call before it did; then lanes, then one try of the scalar loop.
    CHECK(count(choice, 40, 100.0, 300.0, 100000) >= 37);
    CHECK(choice.Mean(1) == Approx(0.001f));
    // Small again: the first call runs as the large ones did, then the scalar loop as before.
    CHECK(count(choice, 10, 3.0, 1.0) <= 2);
    CHECK(crossrt::LaneChoice::SizeClass(1100) == crossrt::LaneChoice::SizeClass(4000));  // [4^5, 4^6)
    CHECK(crossrt::LaneChoice::SizeClass(1000) != crossrt::LaneChoice::SizeClass(100000));
  }
  SECTION("a try of the way that is not the verdict runs on the cores the verdict's last run ran on") {
    crossrt::LaneChoice choice;
    for (int call = 0; call < 2; ++call) {  // lanes, the verdict so far; their loop ran on one core
      crossrt::LaneChoice::Run way = choice.Begin();
      REQUIRE(way.lanes);
      REQUIRE_FALSE(way.trying);
      way.iterations = 1000, way.cores = 0;
      choice.End(way);
    }
    crossrt::LaneChoice::Run tried = choice.Begin();  // the scalar loop, once
    REQUIRE_FALSE(tried.lanes);
    REQUIRE(tried.trying);
    CHECK(tried.verdictCores == 0);
    // A way's ParallelChoice that has measured nothing starts on all cores, but not in a try
    // (unless CROSSRT_CPU_PARALLEL=always puts every loop on all cores).
    const bool always = crossrt::ParallelChoice::AlwaysAllCores() && omp_get_max_threads() > 1;
    crossrt::ParallelChoice fresh, alsoFresh;
    CHECK(fresh.Begin(1000, tried).parallel == always);
    CHECK(tried.cores == (always ? 1 : 0));
    crossrt::LaneChoice::Run verdict{true, 0, std::chrono::steady_clock::now()};
    CHECK(alsoFresh.Begin(1000, verdict).parallel == (omp_get_max_threads() > 1));
    CHECK(verdict.cores == (omp_get_max_threads() > 1 ? 1 : 0));
    tried.verdictCores = 1;
    CHECK(fresh.Begin(1000, tried).parallel == (omp_get_max_threads() > 1));
  }
  SECTION("a run on the cores ParallelChoice is trying counts for neither choice") {
    // The second call of a kernel is where its ParallelChoice tries one core. Counted, that call put
    // one core's time into the lanes' mean, and the scalar loop's try followed it onto one core.
    crossrt::LaneChoice choice;
    auto call = [&](bool coresTried, int cores) {
      crossrt::LaneChoice::Run way = choice.Begin();
      way.iterations = 1000, way.cores = cores, way.coresTried = coresTried;
      choice.End(way);
      return way;
    };
    CHECK(call(false, 1).lanes);  // the first call, on all cores: memory touched, not counted
    CHECK(call(true, 0).lanes);   // lanes on the one core ParallelChoice tries: not counted
    CHECK(choice.Mean(1) < 0.0f);
    CHECK(call(false, 1).lanes);  // lanes on all cores, the verdict's cores: counted
    CHECK(choice.Mean(1) >= 0.0f);
    crossrt::LaneChoice::Run tried = choice.Begin();
    CHECK_FALSE(tried.lanes);
    CHECK(tried.trying);
    CHECK(tried.verdictCores == 1);  // the scalar loop's try runs where the lanes' counted run did
    // The other way round: ParallelChoice leaves a lanes' try out of its means, and tells the way
    // when it tries one core.
    // (With one thread, or CROSSRT_CPU_PARALLEL=always, there is no choice of cores to follow: the
    // loop runs as it must, and its time counts.)
    const bool choosing = omp_get_max_threads() > 1 && !crossrt::ParallelChoice::AlwaysAllCores();
    crossrt::ParallelChoice cores;
    tried.verdictCores = 1;
    const auto followed = cores.Begin(1000, tried);
    CHECK(followed.counted == !choosing);
    cores.End(followed);
    if (choosing) {
      CHECK(cores.Mean(true, 1000) < 0.0f);
      crossrt::LaneChoice::Run verdict{true, 0, std::chrono::steady_clock::now()};
      const auto first = cores.Begin(1000, verdict);  // all cores first, the way the loop is written for
      CHECK(first.parallel);
      CHECK_FALSE(verdict.coresTried);
      CHECK(first.counted);
      // Set times, not End's clock: two empty runs timed on a loaded machine came out in either
      // order, and a one-core try faster than all cores is tried again before it counts (1 in 4
      // runs of this case failed so beside three busy threads on 2 cores).
      cores.Record(first.parallel, 1000, 0.1);
      const auto second = cores.Begin(1000, verdict);  // one core, once, to compare (a fast loop)
      CHECK_FALSE(second.parallel);
      CHECK(verdict.coresTried);
      CHECK(second.counted);  // this choice's own try: in its means
      cores.Record(second.parallel, 1000, 0.2);
      CHECK(cores.Mean(false, 1000) >= 0.0f);
    }
  }
  SECTION("a call with an empty loop counts for nothing") {
    crossrt::LaneChoice choice;
    for (int i = 0; i < 5; ++i) {
      REQUIRE(choice.Choose());
      choice.Record(true, 0, 1.0);
    }
    CHECK(choice.Mean(1) < 0.0f);
    CHECK(choice.Mean(0) < 0.0f);
  }
}

// crossrt::LaneMemory: a kernel's first call in a run takes the way that was faster in the last run
// on this machine (the file CROSSRT_LANE_MEMORY names), the other way is tried after 16 calls (at
// once where its remembered mean is close to the verdict's, new or remembered), and at exit what this run
// measured replaces that kernel's lines, keeping other machines' and kernels'.
// The memory is read as a program with an _ISPC class starts; this test names its file later and
// reads it again (Reload).
TEST_CASE("LaneChoice remembers the faster way for the next run", "[runtime][parallel]")
{
  const std::filesystem::path file = std::filesystem::temp_directory_path() / ("crossrt_lane_memory_" + std::to_string(getpid()) + ".tsv");
  setenv("CROSSRT_LANE_MEMORY", file.c_str(), 1);
  const std::string machine = crossrt::LaneMemory::Machine();
  {
    std::ofstream out(file);
    // This machine's last run: the scalar loop three times faster, in the size class of 1000
    // iterations (4^4 <= 1000 < 4^5); another machine's line, another kernel's, and a broken line.
    out << machine << "\tRemembered::kernel1D_Walk\t4\t0.003\t0.001\t1\t0\n"
        << "Another CPU, avx2, 8 threads\tRemembered::kernel1D_Walk\t4\t0.001\t0.003\t1\t0\n"
        << machine << "\tOther::kernel1D_Scan\t2\t0.5\t0.25\t1\t0\n"
        << machine << "\tOnce::kernel1D_Build\t4\t0.002\t-1\t1\t0\n"  // called once a run: its lanes' first call alone
        << machine << "\tSteady::kernel1D_Step\t4\t0.003\t0.001\t1\t3\n"    // the scalar loop alone in the last 3 runs
        << machine << "\tDue::kernel1D_Step\t4\t0.003\t0.001\t1\t15\n"      // and in the last 15
        << machine << "\tClose::kernel1D_Walk\t4\t0.0012\t0.001\t1\t0\n"    // the lanes within a quarter of the scalar loop
        << machine << "\tStale::kernel1D_Walk\t4\t0.0022\t0.002\t1\t0\n"    // close, from work unlike this run's
        << machine << "\tFar::kernel1D_Walk\t4\t0.02\t0.002\t1\t0\n"        // the lanes 10x behind
        << machine << "\tPending::kernel1D_Walk\t4\t0.009\t0.001\t1\t0\n"   // the lanes far behind
        << machine << "\tBroken::kernel1D_Line\tnot a number\n";
  }
  crossrt::LaneMemory::Get().Reload();
  {
    crossrt::LaneChoice choice("Remembered::kernel1D_Walk");
    if (crossrt::LaneChoice::LanesMode() != crossrt::LaneChoice::Mode::Measure) {
      // CROSSRT_ISPC_LANES=always or never: the memory is neither read nor written.
      CHECK(choice.Choose() == (crossrt::LaneChoice::LanesMode() == crossrt::LaneChoice::Mode::Always));
      std::filesystem::remove(file);
      return;
    }
    int lanes = 0;
    for (int call = 0; call < 16; ++call) {
      const bool l = choice.Choose();
      if (call == 0) CHECK_FALSE(l);  // the first call: the scalar loop, as the last run found faster
      choice.Record(l, 1000, l ? 3.0 : 1.0);
      lanes += l;
    }
    CHECK(lanes == 1);  // lanes tried once in 16 calls
    CHECK(choice.Mean(0) == Approx(0.001f));
    CHECK(choice.Mean(1) == Approx(0.003f));
    // A kernel the file does not name starts in lanes, as in a first run.
    crossrt::LaneChoice fresh("Unremembered::kernel1D_Walk");
    CHECK(fresh.Choose());
    // One whose scalar loop has not run yet runs it (a program's second run), once here: its
    // first call is not counted in this run's means, but it is what the next run compares.
    crossrt::LaneChoice once("Once::kernel1D_Build");
    REQUIRE_FALSE(once.Choose());
    once.Record(false, 1000, 1.0);
    CHECK(once.Mean(0) < 0.0f);
    // Called once a run, the scalar loop the verdict: the 4th such run takes it again, the 16th
    // tries the lanes (its first call then replaces their remembered time).
    crossrt::LaneChoice steady("Steady::kernel1D_Step");
    REQUIRE_FALSE(steady.Choose());
    steady.Record(false, 1000, 1.0);
    crossrt::LaneChoice due("Due::kernel1D_Step");
    bool trying = false;
    REQUIRE(due.Choose(trying));
    CHECK(trying);
    due.Record(true, 1000, 2.0);
    // Remembered lanes within a quarter of the scalar loop's time are tried on the call after the
    // first counted one, not the 16th: another mesh or another build of the kernel may have left
    // them. Faster twice here, they are the verdict from the fourth call on.
    // (The ways `calls` calls take, lanes true, each call taking the time given for its way.)
    const auto ways = [](crossrt::LaneChoice& choice, int calls, double lanesMs, double scalarMs) {
      std::vector<bool> taken;
      for (int call = 0; call < calls; ++call) {
        const bool l = choice.Choose();
        choice.Record(l, 1000, l ? lanesMs : scalarMs);
        taken.push_back(l);
      }
      return taken;
    };
    crossrt::LaneChoice close("Close::kernel1D_Walk");
    CHECK(ways(close, 6, 0.8, 1.0) == std::vector<bool>{false, false, true, true, true, true});
    CHECK(close.Mean(1) == Approx(0.0008f));
    // Remembered within a quarter of the scalar loop's remembered mean, the lanes are tried on the
    // next call too where the scalar loop's new time is half its old one (the last run measured
    // heavier work), and win twice.
    crossrt::LaneChoice stale("Stale::kernel1D_Walk");
    CHECK(ways(stale, 6, 0.7, 1.0) == std::vector<bool>{false, false, true, true, true, true});
    // Ten times behind, they are not, though the scalar loop takes half as long again as it did (a
    // try would cost several calls' time): tried on the 16th call as usual.
    crossrt::LaneChoice far("Far::kernel1D_Walk");
    CHECK(ways(far, 6, 20.0, 3.0) == std::vector<bool>(6, false));
    // The scalar loop as remembered, the lanes far behind: tried on the 16th call, they win once,
    // and the run ends before their second try. That time, not the remembered one, goes to the
    // next run (which then starts in lanes, and measures them again).
    crossrt::LaneChoice pending("Pending::kernel1D_Walk");
    const std::vector<bool> pendingWays = ways(pending, 16, 0.5, 1.0);
    CHECK(std::count(pendingWays.begin(), pendingWays.end(), true) == 1);
    CHECK(pendingWays.back());
    CHECK(pending.Mean(1) == Approx(0.009f));  // not believed in this run yet
  }
  // The choices above are gone: at exit their means are written, here at once.
  REQUIRE(crossrt::LaneMemory::Get().Save());
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  const auto has = [&](const std::string& start) {
    return std::count_if(lines.begin(), lines.end(), [&](const std::string& l) { return l.rfind(start, 0) == 0; });
  };
  CHECK(lines.size() == 10);  // the broken line dropped, the kernel never measured not written
  CHECK(has(machine + "\tClose::kernel1D_Walk\t4\t0.0008\t0.001\t1\t0") == 1);
  CHECK(has(machine + "\tStale::kernel1D_Walk\t4\t0.0007\t0.001\t1\t0") == 1);
  CHECK(has(machine + "\tPending::kernel1D_Walk\t4\t0.0005\t0.001\t1\t0") == 1);
  CHECK(has(machine + "\tFar::kernel1D_Walk\t4\t0.02\t0.003\t1\t1") == 1);
  CHECK(has(machine + "\tOnce::kernel1D_Build\t4\t0.002\t0.001\t1\t0") == 1);  // both ways' first calls now
  CHECK(has(machine + "\tSteady::kernel1D_Step\t4\t0.003\t0.001\t1\t4") == 1);
  CHECK(has(machine + "\tDue::kernel1D_Step\t4\t0.002\t0.001\t1\t0") == 1);
  CHECK(has(machine + "\tRemembered::kernel1D_Walk\t4\t0.003\t0.001\t1\t0") == 1);
  CHECK(has("Another CPU, avx2, 8 threads\tRemembered::kernel1D_Walk\t4\t0.001\t0.003\t1\t0") == 1);
  CHECK(has(machine + "\tOther::kernel1D_Scan\t2\t0.5\t0.25\t1\t0") == 1);
  std::filesystem::remove(file);
}
