// Every construct of the first slice, run by the original class, Constructs_CPU, Constructs_ISPC
// (where ISPC is found) and Constructs_Vulkan (lavapipe, validation on). Tolerances: per-element results within 1e-5
// relative (GPU compilers may fuse multiply-adds); reductions over n values within 1e-4
// relative (the summation order differs); integer results exactly.
#include "Constructs.h"
#include "Constructs_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "Constructs_ISPC.h"
#endif
#include "Constructs_Vulkan.h"
#include "TestSupport.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

namespace {

struct Impls
{
  std::shared_ptr<crossrt::VulkanContext> ctx = ValidatedContext();
  std::vector<std::pair<const char*, std::shared_ptr<Constructs>>> list;
  explicit Impls(int tableSize)
  {
    list.push_back({"original", std::make_shared<Constructs>(tableSize)});
    list.push_back({"CPU", CreateConstructs_CPU(tableSize)});
#ifdef CROSSRT_HAS_ISPC
    list.push_back({"ISPC", CreateConstructs_ISPC(tableSize)});
#endif
    if (ctx) list.push_back({"Vulkan", CreateConstructs_Vulkan(ctx, tableSize)});
  }
};


}  // namespace

TEST_CASE("IPV 1D kernel with helpers, loops, switch and continue", "[equivalence]")
{
  const int n = 100003;  // not a multiple of the workgroup size
  Impls impls(37);
  const auto x = RandomFloats(n, 1, -2.0f, 2.0f);
  std::vector<std::vector<float>> results;
  for (auto& [name, impl] : impls.list)
  {
    auto y = RandomFloats(n, 2, -2.0f, 2.0f);
    impl->CommitDeviceData();
    impl->Saxpy(n, 1.5f, x.data(), y.data());
    results.push_back(y);
  }
  const auto untouched = RandomFloats(n, 2, -2.0f, 2.0f);
  REQUIRE(results[0][3] == untouched[3]);  // 'continue' left element 3 alone
  REQUIRE(results[0][0] != untouched[0]);
  for (size_t k = 1; k < results.size(); ++k)
  {
    INFO(impls.list[k].first);
    REQUIRE(CountMismatches(results[0], results[k], 1e-5f) == 0);
  }
  RequireNoValidationMessages(impls.ctx);
}

TEST_CASE("Member reductions: +=, -=, min, max on float, int, uint and float3", "[equivalence]")
{
  const int n = 70001;
  Impls impls(5);
  const auto values = RandomFloats(n, 3, -2.0f, 2.0f);
  std::vector<float3> points(n);
  const auto coords = RandomFloats(3 * n, 4, -2.0f, 2.0f);
  for (int i = 0; i < n; ++i) points[i] = float3(coords[3 * i], coords[3 * i + 1] * 10.0f, coords[3 * i + 2] - 5.0f);
  // An independent expectation, in double precision.
  double sum = 0.0;
  int positives = 0;
  float mn = INF_POSITIVE;
  for (float v : values) { sum += v; positives += v > 0.0f; mn = std::min(mn, v); }
  for (auto& [name, impl] : impls.list)
  {
    INFO(name);
    impl->CommitDeviceData();
    impl->Stats(n, values.data(), points.data());
    REQUIRE(Close(float(sum), impl->m_sum, 1e-4f));
    REQUIRE(Close(float(-0.5 * sum), impl->m_negSum, 1e-4f));
    REQUIRE(impl->m_min == mn);
    REQUIRE(impl->m_positives == positives);
    REQUIRE(impl->m_maxBits == impls.list[0].second->m_maxBits);
    REQUIRE(impl->m_maxBits > 0u);
    REQUIRE(impl->m_boxMin.y == impls.list[0].second->m_boxMin.y);
    REQUIRE(impl->m_boxMax.z == impls.list[0].second->m_boxMax.z);
    REQUIRE(impl->m_boxMax.y > 19.0f);
  }
  RequireNoValidationMessages(impls.ctx);
}

TEST_CASE("Arrays of user structs with float3 fields", "[equivalence]")
{
  const int n = 1000;
  Impls impls(5);
  std::vector<Particle> in(n);
  const auto r = RandomFloats(8 * n, 5, -2.0f, 2.0f);
  for (int i = 0; i < n; ++i)
    in[i] = {float4(r[8 * i], r[8 * i + 1], r[8 * i + 2], 1.0f), float3(r[8 * i + 3], r[8 * i + 4], r[8 * i + 5]), r[8 * i + 6] + 3.0f};
  std::vector<std::vector<float>> flat;
  for (auto& [name, impl] : impls.list)
  {
    std::vector<Particle> out(n);
    impl->CommitDeviceData();
    impl->Structs(n, in.data(), out.data());
    std::vector<float> f;
    for (auto& p : out) f.insert(f.end(), {p.position.x, p.position.w, p.color.x, p.color.z, p.mass});
    flat.push_back(f);
  }
  REQUIRE(flat[0][4] != 0.0f);
  for (size_t k = 1; k < flat.size(); ++k)
  {
    INFO(impls.list[k].first);
    REQUIRE(CountMismatches(flat[0], flat[k], 1e-5f) == 0);
  }
  RequireNoValidationMessages(impls.ctx);
}

TEST_CASE("RTV kernels called from 1D and 2D loops", "[equivalence]")
{
  const int w = 300, h = 77;
  Impls impls(11);
  std::vector<std::vector<uint32_t>> grids;
  std::vector<std::vector<float>> rows;
  for (auto& [name, impl] : impls.list)
  {
    std::vector<uint32_t> grid(w * h, 12345u);
    std::vector<float> row(w, -1.0f);
    impl->CommitDeviceData();
    impl->Grid(w, h, grid.data(), row.data());
    grids.push_back(grid);
    rows.push_back(row);
  }
  REQUIRE(grids[0][w + 1] != 12345u);
  for (size_t k = 1; k < grids.size(); ++k)
  {
    INFO(impls.list[k].first);
    REQUIRE(grids[k] == grids[0]);
    REQUIRE(CountMismatches(rows[0], rows[k], 1e-5f) == 0);
  }
  RequireNoValidationMessages(impls.ctx);
}

TEST_CASE("IPV 3D kernel with a shifted start and an inclusive bound", "[equivalence]")
{
  const int nx = 19, ny = 13, nz = 9;
  Impls impls(5);
  std::vector<std::vector<float>> vols;
  for (auto& [name, impl] : impls.list)
  {
    std::vector<float> vol(nx * ny * nz, 42.0f);
    impl->CommitDeviceData();
    impl->Volume(nx, ny, nz, vol.data());
    vols.push_back(vol);
  }
  REQUIRE(vols[0][0] == 42.0f);          // row y = 0 is never written
  REQUIRE(vols[0][nx * ny - 1] != 42.0f);  // x = nx-1 is (inclusive bound)
  for (size_t k = 1; k < vols.size(); ++k)
  {
    INFO(impls.list[k].first);
    REQUIRE(CountMismatches(vols[0], vols[k], 1e-5f) == 0);
  }
  RequireNoValidationMessages(impls.ctx);
}

TEST_CASE("A std::vector member resized after CommitDeviceData() is seen at the next call", "[equivalence]")
{
  Impls impls(5);
  for (auto& [name, impl] : impls.list)
  {
    INFO(name);
    impl->m_squares.assign(100, 0);
    impl->CommitDeviceData();
    impl->FillSquares(100);
    impl->m_squares.assign(3000, 0);  // no CommitDeviceData(): the CPU class needs none either
    impl->FillSquares(3000);
    REQUIRE(impl->m_squares[2999] == 2999 * 2999 - 3000);
  }
  RequireNoValidationMessages(impls.ctx);
}

TEST_CASE("A kernel that writes a std::vector member", "[equivalence]")
{
  const int n = 5000;
  Impls impls(5);
  for (auto& [name, impl] : impls.list)
  {
    INFO(name);
    impl->m_squares.assign(n, -7);
    impl->CommitDeviceData();
    impl->FillSquares(n);
    REQUIRE(impl->m_squares[0] == -n);
    REQUIRE(impl->m_squares[n - 1] == (n - 1) * (n - 1) - n);
    REQUIRE(impl->m_squares == impls.list[0].second->m_squares);
  }
  RequireNoValidationMessages(impls.ctx);
}

TEST_CASE("half4: 16-bit floats round to the nearest even, with subnormals, infinities and NaN, on every backend", "[equivalence]")
{
  // Values around every rounding case: ties between halves, subnormal halves, the largest half and
  // beyond (infinity), signed zeros, NaN, and random values over the whole range.
  std::vector<float> values = {0.0f, -0.0f, 1.0f, -1.0f, 65504.0f, 65519.99f, 65520.0f, 1e9f, -1e9f, 6.1035156e-05f, 5.9604645e-08f,
                               2.9802322e-08f, 2.9802326e-08f, 8.9406967e-08f, 1e-10f, std::numeric_limits<float>::infinity(),
                               -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), 1.0009766f, 1.00048828f,
                               1.00146484f, 2049.0f, 2051.0f};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> exponent(-30.0f, 17.0f), sign(-1.0f, 1.0f);
  while (values.size() < 4 * 4001)
    values.push_back(std::copysign(std::exp2(exponent(rng)), sign(rng)));
  const int n = int(values.size() / 4);
  std::vector<float4> in(size_t(n), float4(0.0f));
  std::memcpy(in.data(), values.data(), values.size() * sizeof(float));
  Impls impls(5);
  std::vector<float4> expected;
  for (auto& [name, impl] : impls.list)
  {
    INFO(name);
    for (float scale : {1.0f, 0.5f})
    {
      impl->m_halves.assign(size_t(n), half4(0.0f));
      impl->CommitDeviceData();
      std::vector<float4> out(size_t(n), float4(-7.0f));
      impl->RoundTripHalves(n, scale, in.data(), out.data());
      if (expected.size() < 2 * size_t(n))
        expected.insert(expected.end(), out.begin(), out.end());  // the original's
      size_t differ = 0;
      std::string first;
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < 4; ++c)
        {
          const float e = expected[size_t(scale == 1.0f ? 0 : n) + size_t(i)][c], o = out[size_t(i)][c];
          if ((std::isnan(e) && std::isnan(o)) || std::memcmp(&e, &o, sizeof(float)) == 0)
            continue;  // the same bits (any NaN for a NaN)
          if (differ++ == 0)
            first = std::to_string(in[size_t(i)][c]) + " at scale " + std::to_string(scale) + " gave " + std::to_string(o) + ", the original " +
                    std::to_string(e);
        }
      INFO("the first: " << first);
      REQUIRE(differ == 0);
    }
  }
  RequireNoValidationMessages(impls.ctx);
}

TEST_CASE("Users keep data on the GPU: SetVulkanInOutFor_ and ...Cmd into their own command buffer", "[equivalence]")
{
  auto ctx = ValidatedContext();
  if (!ctx) return;
  const int n = 4099;
  auto x = RandomFloats(n, 11, -2.0f, 2.0f), y = RandomFloats(n, 12, -2.0f, 2.0f);
  Constructs reference(37);
  std::vector<float> expected = y;
  reference.Saxpy(n, 2.0f, x.data(), expected.data());

  auto gpu = std::make_shared<Constructs_Vulkan>(ctx, 37);
  gpu->CommitDeviceData();
  crossrt::Buffer xBuf(ctx, n * sizeof(float)), yBuf(ctx, n * sizeof(float));
  xBuf.Upload(x.data(), n * sizeof(float));
  yBuf.Upload(y.data(), n * sizeof(float));
  gpu->SetVulkanInOutFor_Saxpy(xBuf.View(), yBuf.View());
  VkCommandBuffer cmd = ctx->BeginOneShot();
  gpu->SaxpyCmd(cmd, n, 2.0f, nullptr, nullptr);  // pointers are unused: the bound buffers are
  gpu->crt_UpdatePlainMembers();
  ctx->SubmitAndWait(cmd);
  std::vector<float> result(n);
  yBuf.Download(result.data(), n * sizeof(float));
  REQUIRE(CountMismatches(expected, result, 1e-5f) == 0);

  // The ordinary call reports its times.
  std::vector<float> y2 = y;
  gpu->Saxpy(n, 2.0f, x.data(), y2.data());
  float t[4];
  gpu->GetExecutionTime("Saxpy", t);
  REQUIRE(t[0] > 0.0f);    // GPU time from timestamps
  REQUIRE(t[3] >= t[0]);   // the whole call includes it
  gpu->GetExecutionTime("NoSuchFunction", t);
  REQUIRE(t[3] == 0.0f);
  RequireNoValidationMessages(ctx);
}
