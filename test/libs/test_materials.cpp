// litept's materials, one at a time, as pbrt's and Mitsuba's test suites check theirs:
//   - Sample draws directions with the density Evaluate states: a chi-square test of the drawn
//     directions' histogram against the density integrated over each bin, for every rough material
//     at several roughnesses and incident angles, from both sides of the surface;
//   - a drawn sample's weight is f |cos| / pdf of what Evaluate says of that direction;
//   - every BRDF is reciprocal, and the rough dielectric's BTDF obeys the generalised reciprocity of
//     radiance scaled by 1 / eta^2 (Veach 1997, 5.2);
//   - no NaN or inf at grazing and exactly tangent directions, zero roughness and the ends of the
//     unit interval;
//   - the glTF dielectric's base keeps (1 - F0)(1 - g(n.v)) of a Lambertian base, the weight that
//     scripts/cycles-reference.py gives Cycles to render the same BRDF.
#include "Materials.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace LiteMath;
using namespace litept;

namespace {

// A direction from its polar cosine and azimuth.
float3 Direction(float cosTheta, float phi)
{
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  return float3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
}

// The probability that a chi-square variable with `dof` degrees of freedom exceeds x (the
// Wilson-Hilferty normal approximation, good to a few percent of p at the dof used here).
double ChiSquareTail(double x, int dof)
{
  const double k = dof, z = (std::cbrt(x / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

struct ChiSquareResult
{
  double p = 0.0;         // the chance of a statistic this large if Sample draws Evaluate's density
  double integral = 0.0;  // the density over the whole sphere: the chance that Sample draws anything
  size_t drawn = 0;       // samples that returned a direction
  size_t inconsistent = 0;  // drawn samples whose weight or density disagrees with Evaluate
};

// Draws `count` samples from wo and compares their histogram over (theta, phi) bins of the whole
// sphere, plus a bin for "no sample", with the integral of Evaluate's density over each bin (a
// midpoint rule on a grid fine enough for the sharpest lobe tested, alpha 0.1 refracted, and for
// the integrable peak of the refraction Jacobian at grazing incidence).
ChiSquareResult ChiSquare(const IMaterial& m, float3 wo, size_t count, uint32_t seed)
{
  constexpr int kTheta = 24, kPhi = 32, kSubTheta = 40, kSubPhi = 12;
  const MaterialInputs in = Untextured();
  std::vector<double> observed(kTheta * kPhi + 1, 0.0), expected(kTheta * kPhi + 1, 0.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  ChiSquareResult r;
  for (size_t i = 0; i < count; ++i)
  {
    const float4 u(uniform(rng), uniform(rng), uniform(rng), uniform(rng));
    const BsdfSample s = m.Sample(wo, u, in);
    if (s.weight.w == 0.0f)
    {
      observed.back() += 1.0;
      continue;
    }
    ++r.drawn;
    const float3 wi = to_float3(s.wiPdf);
    const float4 f = m.Evaluate(wo, wi, in);
    const float3 expectedWeight = to_float3(f) * (1.0f / f.w);
    const bool pdfAgrees = std::fabs(f.w - s.wiPdf.w) <= 1e-3f * f.w;
    const bool weightAgrees = std::fabs(expectedWeight.x - s.weight.x) <= 1e-3f * std::max(1.0f, expectedWeight.x) &&
                              std::fabs(expectedWeight.y - s.weight.y) <= 1e-3f * std::max(1.0f, expectedWeight.y) &&
                              std::fabs(expectedWeight.z - s.weight.z) <= 1e-3f * std::max(1.0f, expectedWeight.z);
    r.inconsistent += !pdfAgrees || !weightAgrees;
    const float theta = std::acos(LiteMath::clamp(wi.z, -1.0f, 1.0f));
    const int ti = std::min(kTheta - 1, int(theta / kPi * kTheta));
    float phi = std::atan2(wi.y, wi.x);
    if (phi < 0.0f)
      phi += 2.0f * kPi;
    const int pi = std::min(kPhi - 1, int(phi / (2.0f * kPi) * kPhi));
    observed[size_t(ti * kPhi + pi)] += 1.0;
  }
  // The density's integral over each bin: d(omega) = sin(theta) d(theta) d(phi).
  const double dTheta = kPi / (kTheta * kSubTheta), dPhi = 2.0 * kPi / (kPhi * kSubPhi);
  for (int ti = 0; ti < kTheta; ++ti)
    for (int pi = 0; pi < kPhi; ++pi)
    {
      double sum = 0.0;
      for (int a = 0; a < kSubTheta; ++a)
        for (int b = 0; b < kSubPhi; ++b)
        {
          const double theta = (ti * kSubTheta + a + 0.5) * dTheta;
          const float phi = float((pi * kSubPhi + b + 0.5) * dPhi);
          sum += m.Evaluate(wo, Direction(float(std::cos(theta)), phi), in).w * std::sin(theta);
        }
      expected[size_t(ti * kPhi + pi)] = sum * dTheta * dPhi;
      r.integral += sum * dTheta * dPhi;
    }
  expected.back() = std::max(0.0, 1.0 - r.integral);
  // Bins expected to hold fewer than 5 samples are pooled, as the test requires.
  double chi2 = 0.0, pooledObserved = 0.0, pooledExpected = 0.0;
  int bins = 0;
  for (size_t i = 0; i < expected.size(); ++i)
  {
    const double e = expected[i] * double(count);
    if (e < 5.0)
    {
      pooledObserved += observed[i];
      pooledExpected += e;
      continue;
    }
    chi2 += (observed[i] - e) * (observed[i] - e) / e;
    ++bins;
  }
  if (pooledExpected > 0.0)
  {
    chi2 += (pooledObserved - pooledExpected) * (pooledObserved - pooledExpected) / std::max(pooledExpected, 5.0);
    ++bins;
  }
  r.p = ChiSquareTail(chi2, bins - 1);
  return r;
}

struct Named
{
  std::string name;
  std::shared_ptr<IMaterial> material;
};

// The rough materials (no delta lobes: all they draw has a density) at three roughnesses each.
std::vector<Named> RoughMaterials()
{
  std::vector<Named> out;
  auto lambert = std::make_shared<Lambert>();
  lambert->albedo = float4(0.7f, 0.5f, 0.3f, 0.0f);
  out.push_back({"Lambert", lambert});
  for (float roughness : {0.3f, 0.6f, 1.0f})
    for (float metallic : {0.0f, 1.0f})
    {
      auto m = std::make_shared<GltfMetalRough>();
      m->baseColor = float4(0.8f, 0.6f, 0.4f, 1.0f);
      m->roughness = roughness;
      m->metallic = metallic;
      out.push_back({"GltfMetalRough roughness " + std::to_string(roughness) + " metallic " + std::to_string(metallic), m});
    }
  for (float alpha : {0.1f, 0.3f, 0.7f})
  {
    auto c = std::make_shared<RoughConductor>();
    c->alpha = alpha;
    out.push_back({"RoughConductor alpha " + std::to_string(alpha), c});
    auto d = std::make_shared<Dielectric>();
    d->alpha = alpha;
    out.push_back({"Dielectric alpha " + std::to_string(alpha), d});
    auto p = std::make_shared<Plastic>();
    p->alpha = alpha;
    p->diffuse = float4(0.6f, 0.3f, 0.2f, 0.0f);
    out.push_back({"Plastic alpha " + std::to_string(alpha), p});
  }
  return out;
}

bool Finite(float4 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w); }

}  // namespace

TEST_CASE("materials: Sample draws the density Evaluate states (chi-square), with weights f cos / pdf", "[materials]")
{
  // 19 materials x 3 angles x 2 sides; the significance level is Sidak-corrected for 114 tests at 1%.
  const std::vector<Named> materials = RoughMaterials();
  const double alpha = 1.0 - std::pow(0.99, 1.0 / double(materials.size() * 6));
  uint32_t seed = 1;
  for (const Named& m : materials)
    for (float cosO : {0.95f, 0.6f, 0.15f})
      for (float side : {1.0f, -1.0f})
      {
        const float3 wo = Direction(cosO, 0.7f) * float3(1.0f, 1.0f, side);
        const ChiSquareResult r = ChiSquare(*m.material, wo, 200000, seed++);
        INFO(m.name << ", wo.z = " << wo.z << ": p = " << r.p << ", density integrates to " << r.integral << ", drawn " << r.drawn);
        CHECK(r.drawn > 100000);  // it draws something most of the time
        CHECK(r.integral <= 1.01);
        CHECK(r.p > alpha);
        CHECK(r.inconsistent <= r.drawn / 10000);  // float rounding at the very edges, no more
      }
}

TEST_CASE("materials: every BRDF is reciprocal, the rough dielectric's BTDF scales radiance by 1 / eta^2", "[materials]")
{
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  const MaterialInputs in = Untextured();
  for (const Named& m : RoughMaterials())
  {
    const auto* glass = dynamic_cast<const Dielectric*>(m.material.get());
    size_t compared = 0, failed = 0;
    for (int i = 0; i < 2000; ++i)
    {
      const float3 a = Direction(2.0f * uniform(rng) - 1.0f, 2.0f * kPi * uniform(rng));
      const float3 b = Direction(2.0f * uniform(rng) - 1.0f, 2.0f * kPi * uniform(rng));
      if (std::fabs(a.z) < 0.05f || std::fabs(b.z) < 0.05f)
        continue;
      // f(wo, wi) = Evaluate / |wi.z|.
      const float3 fab = to_float3(m.material->Evaluate(a, b, in)) * (1.0f / std::fabs(b.z));
      const float3 fba = to_float3(m.material->Evaluate(b, a, in)) * (1.0f / std::fabs(a.z));
      float3 expected = fba;
      if (glass && a.z * b.z < 0.0f)
      {
        // Light from b to a crosses from b's medium into a's: f(a, b) / eta_a^2 = f(b, a) / eta_b^2.
        const float etaA = a.z > 0.0f ? 1.0f : glass->ior, etaB = b.z > 0.0f ? 1.0f : glass->ior;
        expected = fba * (etaA * etaA) / (etaB * etaB);
      }
      const float scale = std::max(1e-3f, std::max(fab.x, std::max(fab.y, fab.z)));
      ++compared;
      failed += std::fabs(fab.x - expected.x) > 2e-3f * scale || std::fabs(fab.y - expected.y) > 2e-3f * scale ||
                std::fabs(fab.z - expected.z) > 2e-3f * scale;
    }
    INFO(m.name << ": " << failed << " of " << compared << " pairs not reciprocal");
    CHECK(compared > 1000);
    CHECK(failed == 0);
  }
}

TEST_CASE("materials: no NaN or inf at grazing angles, zero roughness and the ends of the unit interval", "[materials]")
{
  std::vector<Named> materials = RoughMaterials();
  // The smooth ones and the limits of roughness.
  auto glass = std::make_shared<Dielectric>();
  materials.push_back({"smooth Dielectric", glass});
  auto mirror = std::make_shared<RoughConductor>();
  mirror->alpha = 0.0f;
  materials.push_back({"RoughConductor alpha 0", mirror});
  auto justRough = std::make_shared<RoughConductor>();
  justRough->alpha = 1e-3f;
  materials.push_back({"RoughConductor alpha 1e-3", justRough});
  auto smoothPlastic = std::make_shared<Plastic>();
  materials.push_back({"smooth Plastic", smoothPlastic});
  auto polished = std::make_shared<GltfMetalRough>();
  polished->roughness = 0.0f;
  polished->metallic = 0.0f;
  materials.push_back({"GltfMetalRough roughness 0", polished});
  auto polishedMetal = std::make_shared<GltfMetalRough>();
  polishedMetal->roughness = 0.0f;
  materials.push_back({"GltfMetalRough roughness 0 metallic 1", polishedMetal});
  auto roughGlass = std::make_shared<Dielectric>();
  roughGlass->alpha = 1e-3f;
  materials.push_back({"Dielectric alpha 1e-3", roughGlass});

  const float one = 1.0f - 1.0f / 16777216.0f;  // the largest number Random4 gives
  const std::vector<float> us = {0.0f, 1e-7f, 0.25f, 0.5f, 0.999f, one};
  const std::vector<float> cosines = {1.0f, 0.5f, 1e-3f, 1e-6f, 1e-9f, 0.0f, -0.0f, -1e-7f, -0.5f, -1.0f};
  const MaterialInputs in = Untextured();
  for (const Named& m : materials)
  {
    size_t evaluated = 0, bad = 0;
    for (float cosO : cosines)
    {
      const float3 wo = cosO == 0.0f ? float3(1.0f, 0.0f, cosO) : Direction(cosO, 0.3f);
      for (float u0 : us)
        for (float u1 : us)
          for (float u2 : us)
          {
            const BsdfSample s = m.material->Sample(wo, float4(u0, u1, u2, 0.5f), in);
            bad += !Finite(s.weight) || !Finite(s.wiPdf);
            ++evaluated;
          }
      for (float cosI : cosines)
        for (float phi : {0.0f, 0.3f, 0.3f + kPi, 2.0f})
        {
          const float3 wi = cosI == 0.0f ? float3(std::cos(phi), std::sin(phi), cosI) : Direction(cosI, phi);
          bad += !Finite(m.material->Evaluate(wo, wi, in));
          ++evaluated;
        }
      // wi equal to wo and opposite to it: a half vector of zero length.
      bad += !Finite(m.material->Evaluate(wo, wo, in)) + !Finite(m.material->Evaluate(wo, -1.0f * wo, in));
      evaluated += 2;
    }
    INFO(m.name << ": " << bad << " of " << evaluated << " results not finite");
    CHECK(bad == 0);
  }
}

// glTF 2.0's dielectric weighs its Lambertian base by 1 - F(v.h), Schlick's Fresnel of the microfacet
// normal. Seen from a view at cosine mu, the base then keeps (1 - F0)(1 - g(mu)) of the light that
// comes from all directions alike, g(mu) being the integral of (1 - v.h)^5 cos / pi over the
// hemisphere. scripts/cycles-reference.py weighs Cycles' Lambert base so, to render the same BRDF
// (a Fresnel of the shading normal would leave nothing of the base at grazing views); these values
// of g come from a numerical integration in Python (800 x 1600 directions), not from this code.
TEST_CASE("materials: the glTF dielectric's base keeps (1 - F0)(1 - g(n.v)) of a Lambertian base", "[materials]")
{
  struct Expected { float mu, g; };
  const Expected expected[] = {{1.0f, 8.19e-5f}, {0.8f, 9.35e-4f}, {0.5f, 4.957e-3f}, {0.2f, 1.5315e-2f}, {0.05f, 2.4386e-2f}};
  GltfMetalRough white, black;
  white.metallic = black.metallic = 0.0f;
  white.roughness = black.roughness = 1.0f;
  white.baseColor = float4(1.0f);
  black.baseColor = float4(0.0f, 0.0f, 0.0f, 1.0f);
  const MaterialInputs in = Untextured();
  for (const Expected& e : expected)
  {
    // The base's share: the white material's albedo less the black one's (its specular layer),
    // integrated over the hemisphere by the midpoint rule in (cos theta, phi).
    const float3 wo = Direction(e.mu, 0.3f);
    constexpr int kCos = 400, kPhi = 400;
    double base = 0.0;
    for (int a = 0; a < kCos; ++a)
      for (int b = 0; b < kPhi; ++b)
      {
        const float3 wi = Direction((a + 0.5f) / kCos, (b + 0.5f) * 2.0f * kPi / kPhi);
        base += double(white.Evaluate(wo, wi, in).x - black.Evaluate(wo, wi, in).x);
      }
    base *= (1.0 / kCos) * (2.0 * kPi / kPhi);  // d(omega) = d(cos theta) d(phi)
    const double f0 = white.specularF0;
    INFO("n.v " << e.mu << ": the base keeps " << base);
    CHECK(std::fabs(base - (1.0 - f0) * (1.0 - e.g)) < 2e-4);
  }
}
