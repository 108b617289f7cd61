// The path tracer's materials (libs/litept): a virtual hierarchy, so that the translator's virtual
// call levels 1-3 all apply to it (paper 3.9, 4.4). Every method works in the shading frame, where
// +z is the shading normal pointing out of the surface; wo points to where the light goes (the
// camera side), wi to where it comes from. Textures are not reached from here: the integrator looks
// up the textures a material names (TextureIds) and hands the samples in as MaterialInputs.
//
//   Lambert          albedo / pi, two-sided; with an emission (an emitter is a black Lambert).
//   GltfMetalRough   glTF 2.0's metallic-roughness BRDF: GGX (height-correlated Smith, visible-normal
//                    sampling), Schlick Fresnel, a dielectric specular layer over Lambert for
//                    non-metals (fresnel_mix), metal tinted by the base colour; base colour,
//                    metallic-roughness and emissive textures.
//   RoughConductor   GGX with the exact Fresnel of a complex index eta + i k (per channel).
//   Dielectric       glass: smooth (delta reflection and refraction) or rough (GGX reflection and
//                    transmission, Walter et al. 2007), with radiance scaled by 1 / eta^2 on
//                    refraction.
//   Plastic          a Lambert base under a smooth or rough dielectric coat.
#pragma once
#include "Sampling.h"

#include <cstdint>

namespace litept {

using LiteMath::int4;

// What the integrator found in the textures a material names (1 where it names none).
struct MaterialInputs
{
  float4 baseColor;          // the base colour texture's sample (linear rgb, alpha)
  float4 metallicRoughness;  // the glTF metallic-roughness texture's sample: g roughness, b metallic
  float4 emissive;           // the emissive texture's sample (linear rgb)
};

// One direction drawn by a material.
struct BsdfSample
{
  float4 weight;   // xyz: f(wo, wi) |wi.z| / pdf; w: 1 when the sample is valid
  float4 wiPdf;    // xyz: wi (local); w: its density (solid angle), 0 for a delta lobe
  uint32_t flags;  // kBsdfDelta, kBsdfTransmission
};

constexpr uint32_t kBsdfDelta = 1u;         // a mirror or a refraction: no light sampling can find it
constexpr uint32_t kBsdfTransmission = 2u;  // wi is on the other side of the surface

// What a material sees where it names no textures.
inline MaterialInputs Untextured()
{
  MaterialInputs in;
  in.baseColor = float4(1.0f);
  in.metallicRoughness = float4(1.0f);
  in.emissive = float4(1.0f);
  return in;
}

// Marks a sample that failed (absorbed).
inline BsdfSample NoSample()
{
  BsdfSample s;
  s.weight = float4(0.0f);
  s.wiPdf = float4(0.0f);
  s.flags = 0u;
  return s;
}

// Opaque materials are two-sided: seen from below, the frame flips.
inline float3 UpperHemisphere(float3 w, float side) { return float3(w.x, w.y, w.z * side); }

// A delta reflection of wo about the (local) normal with this weight, on wo's side.
inline BsdfSample MirrorSample(float3 wo, float side, float3 weight)
{
  BsdfSample s;
  s.weight = to_float4(weight, 1.0f);
  s.wiPdf = to_float4(UpperHemisphere(float3(-wo.x, -wo.y, wo.z), side), 0.0f);
  s.flags = kBsdfDelta;
  return s;
}

// The sample of direction wi (local) whose evaluation f (Evaluate's f |cos| and density) is given:
// a lobe drawn by the material, weighted by the density of all its lobes together.
inline BsdfSample EvaluatedSample(float3 wi, float4 f, uint32_t flags)
{
  if (f.w <= 0.0f)
    return NoSample();
  BsdfSample s;
  s.weight = to_float4(to_float3(f) * (1.0f / f.w), 1.0f);
  s.wiPdf = to_float4(wi, f.w);
  s.flags = flags;
  return s;
}

struct IMaterial
{
  virtual ~IMaterial() = default;

  // The textures this material samples: x base colour, y metallic-roughness, z normal map, w emissive;
  // -1 for none. Indices into the integrator's m_textures.
  virtual int4 TextureIds() const { return int4(-1, -1, -1, -1); }
  // Emitted radiance towards wo (local).
  virtual float3 Emitted(float3 wo, const MaterialInputs& in) const
  {
    (void)wo, (void)in;
    return float3(0.0f);
  }
  // f(wo, wi) |wi.z| in xyz, and in w the density with which Sample draws wi (delta lobes are not
  // evaluated: 0).
  virtual float4 Evaluate(float3 wo, float3 wi, const MaterialInputs& in) const = 0;
  // Draws wi from four uniform numbers.
  virtual BsdfSample Sample(float3 wo, float4 u, const MaterialInputs& in) const = 0;
};

// ---------------------------------------------------------------- Lambert

struct Lambert : IMaterial
{
  float4 albedo{0.8f, 0.8f, 0.8f, 0.0f};  // xyz: diffuse albedo
  float4 emission{0.0f, 0.0f, 0.0f, 0.0f};  // xyz: radiance emitted from the front side; w: 1 when also from the back
  int baseColorTexture = -1;
  int emissiveTexture = -1;

  int4 TextureIds() const override { return int4(baseColorTexture, -1, -1, emissiveTexture); }
  float3 Emitted(float3 wo, const MaterialInputs& in) const override
  {
    if (wo.z <= 0.0f && emission.w == 0.0f)
      return float3(0.0f);
    return to_float3(emission) * to_float3(in.emissive);
  }
  float4 Evaluate(float3 wo, float3 wi, const MaterialInputs& in) const override
  {
    if (wo.z * wi.z <= 0.0f)
      return float4(0.0f);
    const float cosI = std::fabs(wi.z);
    const float3 f = to_float3(albedo) * to_float3(in.baseColor) * kInvPi;
    return to_float4(f * cosI, cosI * kInvPi);
  }
  BsdfSample Sample(float3 wo, float4 u, const MaterialInputs& in) const override
  {
    const float side = wo.z < 0.0f ? -1.0f : 1.0f;
    const float3 wi = UpperHemisphere(SampleCosineHemisphere(u.x, u.y), side);
    BsdfSample s;
    s.weight = to_float4(to_float3(albedo) * to_float3(in.baseColor), 1.0f);
    s.wiPdf = to_float4(wi, std::fabs(wi.z) * kInvPi);
    s.flags = 0u;
    if (wi.z == 0.0f)
      return NoSample();
    return s;
  }
};

// ---------------------------------------------------------------- glTF metallic-roughness

struct GltfMetalRough : IMaterial
{
  float4 baseColor{1.0f, 1.0f, 1.0f, 1.0f};
  float4 emission{0.0f, 0.0f, 0.0f, 0.0f};  // xyz: emissiveFactor x strength; w: 1 when double-sided
  float metallic = 1.0f;
  float roughness = 1.0f;
  float specularF0 = 0.04f;  // dielectric reflectance at normal incidence: ((ior - 1) / (ior + 1))^2 x specular
  int baseColorTexture = -1;
  int metallicRoughnessTexture = -1;
  int normalTexture = -1;
  int emissiveTexture = -1;

  int4 TextureIds() const override { return int4(baseColorTexture, metallicRoughnessTexture, normalTexture, emissiveTexture); }
  float3 Emitted(float3 wo, const MaterialInputs& in) const override
  {
    if (wo.z <= 0.0f && emission.w == 0.0f)
      return float3(0.0f);
    return to_float3(emission) * to_float3(in.emissive);
  }

  // The lobes' parameters at a point: base colour, GGX alpha, metallic.
  float3 Base(const MaterialInputs& in) const { return to_float3(baseColor) * to_float3(in.baseColor); }
  float Alpha(const MaterialInputs& in) const
  {
    const float r = LiteMath::clamp(roughness * in.metallicRoughness.y, 0.0f, 1.0f);
    return LiteMath::max(r * r, 1e-4f);
  }
  float Metal(const MaterialInputs& in) const { return LiteMath::clamp(metallic * in.metallicRoughness.z, 0.0f, 1.0f); }
  // The chance that Sample picks the specular lobe.
  float SpecularChance(float cosO, float metal) const
  {
    const float f = specularF0 + (1.0f - specularF0) * SchlickWeight(cosO);
    return LiteMath::clamp(metal + (1.0f - metal) * f, 0.05f, 1.0f);
  }

  float4 Evaluate(float3 woIn, float3 wiIn, const MaterialInputs& in) const override
  {
    if (woIn.z * wiIn.z <= 0.0f)
      return float4(0.0f);
    const float side = woIn.z < 0.0f ? -1.0f : 1.0f;
    const float3 wo = UpperHemisphere(woIn, side), wi = UpperHemisphere(wiIn, side);
    const float3 base = Base(in);
    const float alpha = Alpha(in);
    const float metal = Metal(in);
    const float3 h = LiteMath::normalize(wo + wi);
    const float voh = LiteMath::max(LiteMath::dot(wo, h), 0.0f);
    const float fw = SchlickWeight(voh);
    const float dielectricF = specularF0 + (1.0f - specularF0) * fw;
    const float3 metalF = base + (float3(1.0f) - base) * fw;
    const float spec = GgxD(h, alpha) * GgxG2(wo, wi, alpha) / (4.0f * wo.z);  // times wi.z: the cosine is in
    const float3 specular = (metalF * metal + float3(dielectricF) * (1.0f - metal)) * spec;
    const float3 diffuse = base * ((1.0f - metal) * (1.0f - dielectricF) * kInvPi * wi.z);
    const float chance = SpecularChance(wo.z, metal);
    const float pdf = chance * GgxReflectionPdf(wo, h, alpha) + (1.0f - chance) * wi.z * kInvPi;
    return to_float4(specular + diffuse, pdf);
  }

  BsdfSample Sample(float3 woIn, float4 u, const MaterialInputs& in) const override
  {
    const float side = woIn.z < 0.0f ? -1.0f : 1.0f;
    const float3 wo = UpperHemisphere(woIn, side);
    if (wo.z <= 0.0f)
      return NoSample();
    const float chance = SpecularChance(wo.z, Metal(in));
    float3 wi;
    if (u.z < chance)
    {
      const float3 h = SampleGgxVisibleNormal(wo, Alpha(in), u.x, u.y);
      wi = LiteMath::reflect(-1.0f * wo, h);
    }
    else
      wi = SampleCosineHemisphere(u.x, u.y);
    if (wi.z <= 0.0f)
      return NoSample();
    const float3 wiOut = UpperHemisphere(wi, side);
    return EvaluatedSample(wiOut, Evaluate(woIn, wiOut, in), 0u);
  }
};

// ---------------------------------------------------------------- rough conductor

struct RoughConductor : IMaterial
{
  float4 eta{0.2f, 0.92f, 1.1f, 0.0f};  // the real part of the index (default: gold)
  float4 k{3.91f, 2.45f, 2.14f, 0.0f};  // the imaginary part
  float4 tint{1.0f, 1.0f, 1.0f, 0.0f};  // a factor on the reflectance
  float alpha = 0.1f;                    // GGX alpha (roughness squared); below 1e-3 a mirror

  float4 Evaluate(float3 woIn, float3 wiIn, const MaterialInputs& in) const override
  {
    (void)in;
    if (woIn.z * wiIn.z <= 0.0f || alpha < 1e-3f)
      return float4(0.0f);
    const float side = woIn.z < 0.0f ? -1.0f : 1.0f;
    const float3 wo = UpperHemisphere(woIn, side), wi = UpperHemisphere(wiIn, side);
    const float3 h = LiteMath::normalize(wo + wi);
    const float3 f = FresnelConductor(LiteMath::max(LiteMath::dot(wo, h), 0.0f), to_float3(eta), to_float3(k)) * to_float3(tint);
    const float spec = GgxD(h, alpha) * GgxG2(wo, wi, alpha) / (4.0f * wo.z);
    return to_float4(f * spec, GgxReflectionPdf(wo, h, alpha));
  }

  BsdfSample Sample(float3 woIn, float4 u, const MaterialInputs& in) const override
  {
    (void)in;
    const float side = woIn.z < 0.0f ? -1.0f : 1.0f;
    const float3 wo = UpperHemisphere(woIn, side);
    if (wo.z <= 0.0f)
      return NoSample();
    if (alpha < 1e-3f)  // a mirror
      return MirrorSample(wo, side, FresnelConductor(wo.z, to_float3(eta), to_float3(k)) * to_float3(tint));
    BsdfSample s;
    const float3 h = SampleGgxVisibleNormal(wo, alpha, u.x, u.y);
    const float3 wi = LiteMath::reflect(-1.0f * wo, h);
    if (wi.z <= 0.0f)
      return NoSample();
    const float3 f = FresnelConductor(LiteMath::max(LiteMath::dot(wo, h), 0.0f), to_float3(eta), to_float3(k)) * to_float3(tint);
    s.weight = to_float4(f * (GgxG2(wo, wi, alpha) / GgxG1(wo, alpha)), 1.0f);
    s.wiPdf = to_float4(UpperHemisphere(wi, side), GgxReflectionPdf(wo, h, alpha));
    s.flags = 0u;
    return s;
  }
};

// ---------------------------------------------------------------- dielectric (glass)

struct Dielectric : IMaterial
{
  float4 tint{1.0f, 1.0f, 1.0f, 0.0f};  // a factor on reflection and transmission (glTF's base colour)
  float ior = 1.5f;                      // inside over outside (the normal points outside)
  float alpha = 0.0f;                    // GGX alpha; below 1e-3 smooth glass

  float4 Evaluate(float3 wo, float3 wi, const MaterialInputs& in) const override
  {
    (void)in;
    if (alpha < 1e-3f || wo.z == 0.0f || wi.z == 0.0f)
      return float4(0.0f);
    const bool reflect = wo.z * wi.z > 0.0f;
    const float eta = wo.z > 0.0f ? ior : 1.0f / ior;  // the far side's index over this side's
    float3 h = reflect ? wo + wi : wo + wi * eta;
    if (LiteMath::dot(h, h) == 0.0f)
      return float4(0.0f);
    h = LiteMath::normalize(h);
    if (h.z < 0.0f)
      h = -1.0f * h;
    const float woh = LiteMath::dot(wo, h), wih = LiteMath::dot(wi, h);
    if (woh * wo.z <= 0.0f || wih * wi.z <= 0.0f)  // microfacets seen from behind
      return float4(0.0f);
    const float F = FresnelDielectric(woh, ior);
    const float3 woUp = UpperHemisphere(wo, wo.z < 0.0f ? -1.0f : 1.0f);
    const float3 wiUp = UpperHemisphere(wi, wi.z < 0.0f ? -1.0f : 1.0f);
    const float D = GgxD(h, alpha);
    const float G2 = GgxG2(woUp, wiUp, alpha);
    const float G1 = GgxG1(woUp, alpha);
    const float absWoZ = std::fabs(wo.z);
    if (reflect)
    {
      const float value = F * D * G2 / (4.0f * absWoZ);
      const float pdf = F * G1 * D / (4.0f * absWoZ);  // visible normal density over 4 |wo.h|, times F
      return to_float4(to_float3(tint) * value, pdf);
    }
    const float denom = wih * eta + woh;
    const float dwh = std::fabs(wih) / (denom * denom);  // d(h) / d(wi), before eta^2
    // f |wi.z| with radiance scaled by 1 / eta^2 (the eta^2 of the Jacobian cancels it).
    const float value = (1.0f - F) * D * G2 * std::fabs(woh) * dwh / absWoZ;
    const float pdf = (1.0f - F) * G1 * std::fabs(woh) * D / absWoZ * dwh * eta * eta;
    return to_float4(to_float3(tint) * value, pdf);
  }

  BsdfSample Sample(float3 wo, float4 u, const MaterialInputs& in) const override
  {
    if (wo.z == 0.0f)
      return NoSample();
    const float side = wo.z < 0.0f ? -1.0f : 1.0f;
    const float eta = wo.z > 0.0f ? ior : 1.0f / ior;
    float3 h = float3(0.0f, 0.0f, side);  // the (micro)normal on wo's side: mirrored in z, as wo is
    if (alpha >= 1e-3f)
      h = UpperHemisphere(SampleGgxVisibleNormal(UpperHemisphere(wo, side), alpha, u.x, u.y), side);
    const float F = FresnelDielectric(LiteMath::dot(wo, h) * side, ior);
    float3 wi;
    uint32_t flags = alpha < 1e-3f ? kBsdfDelta : 0u;
    if (u.z < F)
      wi = LiteMath::reflect(-1.0f * wo, h);
    else
    {
      wi = LiteMath::refract(-1.0f * wo, h, 1.0f / eta);
      flags |= kBsdfTransmission;
      if (LiteMath::dot(wi, wi) == 0.0f)
        return NoSample();
    }
    const bool reflected = (flags & kBsdfTransmission) == 0u;
    if ((wi.z * wo.z > 0.0f) != reflected || wi.z == 0.0f)
      return NoSample();
    BsdfSample s;
    s.flags = flags;
    if (alpha < 1e-3f)
    {
      // The Fresnel choice cancels F; refraction scales radiance by 1 / eta^2.
      const float scale = reflected ? 1.0f : 1.0f / (eta * eta);
      s.weight = to_float4(to_float3(tint) * scale, 1.0f);
      s.wiPdf = to_float4(wi, 0.0f);
      return s;
    }
    return EvaluatedSample(wi, Evaluate(wo, wi, in), flags);
  }
};

// ---------------------------------------------------------------- plastic

struct Plastic : IMaterial
{
  float4 diffuse{0.5f, 0.5f, 0.5f, 0.0f};  // the base's albedo
  float ior = 1.5f;                         // the coat's
  float alpha = 0.0f;                       // the coat's GGX alpha; below 1e-3 smooth
  float diffuseChance = 0.5f;               // how often Sample picks the base (set from the albedo)

  // The fraction of light that the coat lets through, in and out, for the base.
  float Transmitted(float3 wo, float3 wi) const { return (1.0f - FresnelDielectric(wo.z, ior)) * (1.0f - FresnelDielectric(wi.z, ior)); }

  float4 Evaluate(float3 woIn, float3 wiIn, const MaterialInputs& in) const override
  {
    (void)in;
    if (woIn.z * wiIn.z <= 0.0f)
      return float4(0.0f);
    const float side = woIn.z < 0.0f ? -1.0f : 1.0f;
    const float3 wo = UpperHemisphere(woIn, side), wi = UpperHemisphere(wiIn, side);
    // Internal reflections at the coat brighten and saturate the base: 1 / (1 - albedo x Fdr),
    // Fdr ~ 0.6 for ior 1.5 seen from inside.
    const float3 kd = to_float3(diffuse);
    const float3 base = kd * (1.0f / (ior * ior)) / (float3(1.0f) - kd * 0.6f);
    float3 value = base * (Transmitted(wo, wi) * kInvPi * wi.z);
    float pdf = diffuseChance * wi.z * kInvPi;
    if (alpha >= 1e-3f)
    {
      const float3 h = LiteMath::normalize(wo + wi);
      const float F = FresnelDielectric(LiteMath::dot(wo, h), ior);
      value = value + float3(F * GgxD(h, alpha) * GgxG2(wo, wi, alpha) / (4.0f * wo.z));
      pdf = pdf + (1.0f - diffuseChance) * GgxReflectionPdf(wo, h, alpha);
    }
    return to_float4(value, pdf);
  }

  BsdfSample Sample(float3 woIn, float4 u, const MaterialInputs& in) const override
  {
    const float side = woIn.z < 0.0f ? -1.0f : 1.0f;
    const float3 wo = UpperHemisphere(woIn, side);
    if (wo.z <= 0.0f)
      return NoSample();
    if (u.z >= diffuseChance)  // the coat
    {
      if (alpha < 1e-3f)
        return MirrorSample(wo, side, float3(FresnelDielectric(wo.z, ior) / (1.0f - diffuseChance)));
      const float3 h = SampleGgxVisibleNormal(wo, alpha, u.x, u.y);
      const float3 wi = LiteMath::reflect(-1.0f * wo, h);
      if (wi.z <= 0.0f)
        return NoSample();
      return EvaluatedSample(UpperHemisphere(wi, side), Evaluate(woIn, UpperHemisphere(wi, side), in), 0u);
    }
    const float3 wi = SampleCosineHemisphere(u.x, u.y);
    if (wi.z <= 0.0f)
      return NoSample();
    return EvaluatedSample(UpperHemisphere(wi, side), Evaluate(woIn, UpperHemisphere(wi, side), in), 0u);
  }
};

}  // namespace litept
