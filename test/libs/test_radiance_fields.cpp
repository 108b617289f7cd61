// ReLU fields (libs/literf): the renderers against closed forms, the occupied-cell tree's order, the
// analytic gradients against finite differences, training on images of an analytic scene, the
// NeRF dataset reader's errors, the model file, and ReluField_CPU and ReluField_Vulkan (validation
// on) against the original.
#include "NerfDataset.h"
#include "RFCellTree.h"
#include "RFTraining.h"
#include "ReluField.h"
#include "ReluField_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "ReluField_ISPC.h"
#endif
#include "ReluField_Vulkan.h"
#include "TestSupport.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

using namespace literf;
using LiteMath::float3;
using LiteMath::float4;
using LiteMath::float4x4;

namespace {

// A camera at `eye` looking at the origin, as a NeRF camera-to-world matrix (looks down -z, y up).
float4x4 LookAtOrigin(float3 eye)
{
  const float3 back = LiteMath::normalize(eye);
  const float3 right = LiteMath::normalize(LiteMath::cross(float3(0.0f, 1.0f, 0.0f), back));
  const float3 up = LiteMath::cross(back, right);
  return float4x4(right.x, up.x, back.x, eye.x, right.y, up.y, back.y, eye.y, right.z, up.z, back.z, eye.z, 0.0f, 0.0f, 0.0f, 1.0f);
}

// Exposes the gradients of one batch without the Adam step.
class GradientProbe : public ReluField
{
public:
  GradientProbe() : ReluField(1, 1) {}
  std::vector<float> Gradients(const std::vector<float4>& o, const std::vector<float4>& d, const std::vector<float4>& target, float& loss)
  {
    const int rays = int(o.size());
    m_gradientScale = 1.0f / float(rays);
    kernel1D_ZeroGradients(int(m_values.size()));
    std::vector<float> losses(o.size());
    kernel1D_Backward(rays, o.data(), d.data(), target.data(), losses.data());
    loss = 0.0f;
    for (float l : losses)
      loss += l / float(rays);
    return m_gradients;
  }
  float Loss(const std::vector<float4>& o, const std::vector<float4>& d, const std::vector<float4>& target)
  {
    float loss;
    Gradients(o, d, target, loss);
    return loss;
  }
  std::vector<float>& Values() { return m_values; }
};

// Rays from points around the box towards points inside it.
void RandomRays(int n, unsigned seed, std::vector<float4>& o, std::vector<float4>& d)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < n; ++i)
  {
    const float3 from = LiteMath::normalize(float3(u(rng), u(rng), u(rng))) * 4.0f;
    const float3 to = float3(u(rng), u(rng), u(rng)) * 0.8f;
    const float3 dir = LiteMath::normalize(to - from);
    o.push_back(float4(from.x, from.y, from.z, 0.0f));
    d.push_back(float4(dir.x, dir.y, dir.z, 0.0f));
  }
}

// The length of the ray's chord through the box [lo, hi].
float Chord(float3 o, float3 d, float3 lo, float3 hi)
{
  float enter = 0.0f, leave = 1e30f;
  for (int a = 0; a < 3; ++a)
  {
    const float t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
    enter = std::max(enter, std::min(t0, t1));
    leave = std::min(leave, std::max(t0, t1));
  }
  return std::max(leave - enter, 0.0f);
}

// An analytic scene: an opaque sphere of radius 0.8 whose colour is 0.5 + 0.4 * its normal, on
// white. Rendered by ray/sphere intersection, independently of literf's renderers.
float4 SpherePixel(float3 o, float3 d)
{
  const float b = LiteMath::dot(o, d), c = LiteMath::dot(o, o) - 0.64f, disc = b * b - c;
  if (disc < 0.0f)
    return float4(1.0f, 1.0f, 1.0f, 1.0f);
  const float3 n = LiteMath::normalize(o + d * (-b - std::sqrt(disc)));
  return float4(0.5f + 0.4f * n.x, 0.5f + 0.4f * n.y, 0.5f + 0.4f * n.z, 1.0f);
}

NerfSplit SphereSplit(int views, int size, unsigned seed)
{
  NerfSplit s;
  s.cameraAngleX = 0.7f;
  s.width = s.height = size;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int v = 0; v < views; ++v)
  {
    // On the upper hemisphere of radius 4, as the NeRF synthetic scenes' cameras.
    const float phi = 6.2831853f * u(rng), z = 0.1f + 0.85f * u(rng), r = std::sqrt(1.0f - z * z);
    NerfFrame f;
    f.filePath = "./views/r_" + std::to_string(v);
    f.cameraToWorld = LookAtOrigin(float3(r * std::cos(phi), z, r * std::sin(phi)) * 4.0f);
    f.image = LiteImage::Image2D<float4>(uint32_t(size), uint32_t(size));
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
      {
        float3 o, d;
        PixelRay(f.cameraToWorld, s.Focal(), size, size, x, y, o, d);
        f.image.data()[y * size + x] = SpherePixel(o, d);
      }
    s.frames.push_back(std::move(f));
  }
  return s;
}

}  // namespace

TEST_CASE("a uniform field renders the closed form on both methods", "[rf]")
{
  // Density sigma and colour c everywhere: C = c (1 - exp(-sigma L)) + exp(-sigma L), L the chord.
  RFGrid grid = MakeGrid(6, 0, 0.012f, float3(-1.5f), float3(1.5f));  // sigma = 1.2
  const float zc = 0.7f, c = 1.0f / (1.0f + std::exp(-zc * 0.28209479f));
  for (size_t v = 0; v < grid.values.size(); v += size_t(grid.Channels()))
    grid.values[v + 1] = grid.values[v + 2] = grid.values[v + 3] = zc;
  const int size = 24;
  for (int method : {ReluField::kMarch, ReluField::kCells})
  {
    ReluField field(size, size);
    field.SetGrid(grid);
    field.SetMethod(method);
    field.SetStopTransmittance(0.0f);
    const float4x4 camera = LookAtOrigin(float3(1.0f, 2.0f, 3.5f));
    const float focal = 20.0f;
    field.SetCamera(camera, focal);
    std::vector<float4> image(size * size);
    field.Render(image.data());
    int hits = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
      {
        float3 o, d;
        PixelRay(camera, focal, size, size, x, y, o, d);
        const float L = Chord(o, d, float3(-1.5f), float3(1.5f));
        hits += L > 0.0f;
        const float T = std::exp(-1.2f * L), expected = c * (1.0f - T) + T;
        INFO("method " << method << " pixel " << x << "," << y << " chord " << L);
        REQUIRE(image[y * size + x].x == Approx(expected).margin(2e-5));
        REQUIRE(image[y * size + x].z == Approx(expected).margin(2e-5));
      }
    REQUIRE(hits > size * size / 4);
  }
}

TEST_CASE("the occupied-cell tree holds every occupied cell once, children apart, and is visited front to back", "[rf]")
{
  // Random raw densities: about half the vertices positive.
  RFGrid grid = MakeGrid(9, 1, 0.0f, float3(-1.0f, -2.0f, -1.5f), float3(2.0f, 1.0f, 1.5f));
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 0.6f);
  for (size_t v = 0; v < grid.values.size(); v += size_t(grid.Channels()))
    grid.values[v] = u(rng) < 0.0f ? -1.0f : 0.05f;
  const std::vector<uint8_t> occupied = OccupiedCells(grid);
  const std::vector<RFNode> nodes = BuildCellTree(grid);
  std::vector<int> seen(occupied.size(), 0);
  for (const RFNode& n : nodes)
    if (n.left & kCellLeaf)
      seen[n.left & ~kCellLeaf] += 1;
    else
    {
      const RFNode &a = nodes[n.left], &b = nodes[n.left + 1];
      REQUIRE(a.boxMax[int(n.axis)] <= b.boxMin[int(n.axis)]);
    }
  size_t count = 0;
  for (size_t i = 0; i < occupied.size(); ++i)
  {
    REQUIRE(seen[i] == int(occupied[i]));
    count += occupied[i];
  }
  REQUIRE(count > 100);
  REQUIRE(nodes.size() == 2 * count - 1);

  // The order of the visit: a field of smooth, positive density (so that one sample per cell
  // stays close to the integral) whose colours differ from vertex to vertex. One sample per cell
  // against constant steps of 1/40 cell agree within 0.05 per channel; visiting cells out of order
  // would put the wrong colours in front.
  std::uniform_real_distribution<float> colour(-4.0f, 4.0f);
  for (int z = 0; z <= grid.cells; ++z)
    for (int y = 0; y <= grid.cells; ++y)
      for (int x = 0; x <= grid.cells; ++x)
      {
        float* v = &grid.values[size_t(x + 10 * (y + 10 * z)) * size_t(grid.Channels())];
        v[0] = 0.004f + 0.002f * std::sin(0.7f * float(x + 2 * y - z));
        v[1] = colour(rng);
        v[5] = colour(rng);
        v[9] = colour(rng);
      }
  ReluField cells(32, 32), march(32, 32);
  for (ReluField* f : {&cells, &march})
  {
    f->SetGrid(grid);
    f->SetStopTransmittance(0.0f);
    f->SetCamera(LookAtOrigin(float3(-2.0f, 1.0f, 4.0f)), 30.0f);
  }
  march.SetMethod(ReluField::kMarch);
  march.SetMarchStep(0.025f);
  std::vector<float4> a(32 * 32), b(32 * 32);
  cells.Render(a.data());
  march.Render(b.data());
  float worst = 0.0f, changed = 0.0f;
  for (size_t i = 0; i < a.size(); ++i)
  {
    worst = std::max(worst, std::max(std::fabs(a[i].x - b[i].x), std::max(std::fabs(a[i].y - b[i].y), std::fabs(a[i].z - b[i].z))));
    changed = std::max(changed, 3.0f - a[i].x - a[i].y - a[i].z);
  }
  REQUIRE(changed > 0.3f);  // the field shows
  REQUIRE(worst < 0.05f);
}

TEST_CASE("gradients of the loss match finite differences", "[rf]")
{
  RFGrid grid = MakeGrid(3, 1, 0.0f, float3(-1.0f), float3(1.0f));
  grid.densityScale = 4.0f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.15f, 0.6f), coefficient(-1.0f, 1.0f);
  for (size_t i = 0; i < grid.values.size(); ++i)
    grid.values[i] = i % size_t(grid.Channels()) == 0 ? u(rng) : coefficient(rng);
  grid.values[0] = -0.3f;  // a vertex below zero (its cells' interpolants still reach above)
  GradientProbe probe;
  probe.SetGrid(grid);
  probe.SetStopTransmittance(0.0f);
  probe.SetMarchStep(0.3f);
  std::vector<float4> o, d, target;
  RandomRays(48, 11, o, d);
  for (int i = 0; i < 48; ++i)
    target.push_back(float4(0.2f + 0.01f * i, 0.5f, 0.9f - 0.01f * i, 1.0f));
  float loss = 0.0f;
  const std::vector<float> analytic = probe.Gradients(o, d, target, loss);
  REQUIRE(loss > 0.01f);
  int checked = 0, nonzero = 0;
  for (size_t i = 1; i < analytic.size(); i += 3)
  {
    const float h = 1e-3f, keep = probe.Values()[i];
    probe.Values()[i] = keep + h;
    const float up = probe.Loss(o, d, target);
    probe.Values()[i] = keep - h;
    const float down = probe.Loss(o, d, target);
    probe.Values()[i] = keep;
    const float numeric = (up - down) / (2.0f * h);
    INFO("value " << i << ": analytic " << analytic[i] << ", finite differences " << numeric);
    REQUIRE(std::fabs(analytic[i] - numeric) <= 2e-3f * std::max(std::fabs(numeric), 1e-2f) + 2e-5f);
    ++checked;
    nonzero += std::fabs(numeric) > 1e-4f;
  }
  REQUIRE(checked > 100);
  REQUIRE(nonzero > 30);  // the rays reach only some vertices
}

TEST_CASE("training on images of an analytic scene reaches a test PSNR", "[rf]")
{
  const NerfSplit train = SphereSplit(24, 32, 1), test = SphereSplit(4, 32, 2);
  auto field = CreateReluField_CPU(32, 32);
  TrainOptions options;
  options.stages = {8, 16};
  options.iterations = 120;
  options.batch = 1024;
  options.shDegree = 1;
  float lastLoss = 1.0f, firstLoss = 0.0f;
  RFGrid trained = Train(*field, train, options, [&](const TrainProgress& p) {
    if (p.stage == 0 && p.iteration == 1)
      firstLoss = p.loss;
    lastLoss = p.loss;
  });
  REQUIRE(trained.cells == 16);
  REQUIRE(lastLoss < 0.25f * firstLoss);
  ReluField render(32, 32);
  RFGrid initial = MakeGrid(8, 1, options.initialRawDensity, options.boxMin, options.boxMax);
  render.SetGrid(initial);
  const float before = SplitPsnr(render, test);
  render.SetGrid(trained);
  const float after = SplitPsnr(render, test);
  render.SetMethod(ReluField::kMarch);
  const float afterMarch = SplitPsnr(render, test);
  INFO("test PSNR " << before << " dB before training, " << after << " dB after (" << afterMarch << " dB marching); loss " << firstLoss << " -> "
                    << lastLoss);
  REQUIRE(after > 20.0f);
  REQUIRE(after > before + 8.0f);
  // The march agrees with the cells on the trained field within 1.5 dB.
  REQUIRE(std::fabs(afterMarch - after) < 1.5f);
}

TEST_CASE("ReluField_CPU, ReluField_ISPC and ReluField_Vulkan render and train as the original", "[rf]")
{
  RFGrid grid = MakeGrid(6, 2, 0.0f, float3(-1.5f), float3(1.5f));
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.02f, 0.03f), coefficient(-1.0f, 1.0f);
  for (size_t i = 0; i < grid.values.size(); ++i)
    grid.values[i] = i % size_t(grid.Channels()) == 0 ? u(rng) : coefficient(rng);
  const int size = 20;
  std::vector<float4> o, d, target;
  RandomRays(256, 4, o, d);
  for (size_t i = 0; i < o.size(); ++i)
    target.push_back(float4(0.3f, 0.6f, 0.2f, 1.0f));

  // Renders with both methods and takes three training steps; returns the images and the values.
  auto run = [&](ReluField& field, std::vector<float4>& cells, std::vector<float4>& march, std::vector<float>& values) {
    field.SetGrid(grid);
    field.CommitDeviceData();
    field.SetCamera(LookAtOrigin(float3(2.0f, 1.5f, 3.0f)), 25.0f);
    cells.resize(size * size);
    march.resize(size * size);
    field.SetMethod(ReluField::kCells);
    field.Render(cells.data());
    field.SetMethod(ReluField::kMarch);
    field.Render(march.data());
    std::vector<float> losses(o.size());
    for (int step = 0; step < 3; ++step)
      field.TrainStep(int(o.size()), o.data(), d.data(), target.data(), losses.data());
    values.resize(grid.values.size());
    field.ReadValues(int(values.size()), values.data());
  };
  ReluField original(size, size);
  std::vector<float4> cells0, march0;
  std::vector<float> values0;
  run(original, cells0, march0, values0);
  REQUIRE(values0 != grid.values);  // the steps moved it

  auto compare = [&](ReluField& field, float tolerance) {
    std::vector<float4> cells, march;
    std::vector<float> values;
    run(field, cells, march, values);
    for (size_t i = 0; i < cells.size(); ++i)
    {
      INFO("pixel " << i);
      REQUIRE(std::fabs(cells[i].x - cells0[i].x) <= tolerance);
      REQUIRE(std::fabs(cells[i].z - cells0[i].z) <= tolerance);
      REQUIRE(std::fabs(march[i].y - march0[i].y) <= tolerance);
    }
    // Adam normalises each step to about the learning rate, so a value moves by at most ~0.09:
    // atomics sum gradients in another order, which may flip tiny gradients' steps.
    size_t off = 0;
    for (size_t i = 0; i < values.size(); ++i)
      off += std::fabs(values[i] - values0[i]) > 1e-3f;
    INFO(off << " of " << values.size() << " values differ by more than 1e-3");
    REQUIRE(off <= values.size() / 200);
  };
  SECTION("_CPU")
  {
    auto cpu = CreateReluField_CPU(size, size);
    compare(*cpu, 1e-6f);
  }
#ifdef CROSSRT_HAS_ISPC
  SECTION("_ISPC")
  {
    auto lanes = CreateReluField_ISPC(size, size);
    compare(*lanes, 2e-5f);  // ISPC's exp and log are not the C library's
  }
#endif
  SECTION("_Vulkan")
  {
    auto ctx = ValidatedContext();
    if (!ctx)
      return;
    ReluField_Vulkan vulkan(ctx, size, size);
    compare(vulkan, 2e-4f);
    RequireNoValidationMessages(ctx);
  }
}

TEST_CASE("NeRF splits: a round trip, and clear errors for broken datasets", "[rf]")
{
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crossrt_nerf_test";
  std::filesystem::remove_all(dir);
  NerfSplit split = SphereSplit(3, 16, 9);
  SaveNerfSplit(dir.string(), "train", split);
  const NerfSplit back = LoadNerfSplit(dir.string(), "train");
  REQUIRE(back.frames.size() == 3);
  REQUIRE(back.width == 16);
  REQUIRE(back.cameraAngleX == Approx(0.7f));
  REQUIRE(back.frames[2].cameraToWorld(0, 3) == Approx(split.frames[2].cameraToWorld(0, 3)));
  REQUIRE(Psnr(back.frames[1].image, split.frames[1].image) > 45.0f);  // 8-bit PNG

  auto fails = [&](const std::string& expected) {
    try
    {
      LoadNerfSplit(dir.string(), "train");
    }
    catch (const std::runtime_error& e)
    {
      INFO(e.what());
      REQUIRE(std::string(e.what()).find(expected) != std::string::npos);
      return;
    }
    FAIL("no error");
  };
  const std::filesystem::path json = dir / "transforms_train.json";
  std::string text;
  {
    std::ifstream in(json);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto write = [&](const std::string& t) { std::ofstream(json) << t; };
  write(text.substr(0, text.size() / 2));
  fails("malformed JSON");
  write("{\"frames\": []}");
  fails("no number camera_angle_x");
  write("{\"camera_angle_x\": 0.7, \"frames\": [{\"file_path\": \"./views/r_0\", \"transform_matrix\": [[1,0,0]]}]}");
  fails("transform_matrix is not 4 rows of 4 numbers");
  write(text);
  std::filesystem::remove(dir / "views" / "r_1.png");
  fails("cannot read the image");
  std::filesystem::remove_all(dir);
  fails("cannot open");
}

TEST_CASE("model files: a round trip, and clear errors for other versions and damage", "[rf]")
{
  const std::string path = (std::filesystem::temp_directory_path() / "crossrt_rf_model.bin").string();
  RFGrid grid = MakeGrid(4, 2, 0.25f, float3(-1.0f), float3(2.0f));
  grid.values[17] = -3.5f;
  SaveModel(path, grid);
  const RFGrid back = LoadModel(path);
  REQUIRE(back.values == grid.values);
  REQUIRE(back.shDegree == 2);
  REQUIRE(back.boxMax.x == 2.0f);
  // Version 2 in the header.
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(8);
    const uint32_t version = 2;
    f.write(reinterpret_cast<const char*>(&version), 4);
  }
  REQUIRE_THROWS_WITH(LoadModel(path), Catch::Contains("model version 2"));
  SaveModel(path, grid);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 8);
  REQUIRE_THROWS_WITH(LoadModel(path), Catch::Contains("cut short"));
  REQUIRE_THROWS_WITH(LoadModel(path + ".missing"), Catch::Contains("cannot open"));
  grid.shDegree = 3;
  REQUIRE(Problem(grid).find("degree") != std::string::npos);
  std::filesystem::remove(path);
}
