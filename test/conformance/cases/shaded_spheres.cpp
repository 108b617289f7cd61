#include "shaded_spheres.h"

ShadedSpheres::ShadedSpheres() : m_light(normalize(float3(1.0f, 1.0f, 2.0f)))
{
  auto a = std::make_shared<Lambert>();
  a->albedo = float3(0.8f, 0.4f, 0.2f);
  auto b = std::make_shared<Mirror>();
  b->tint = float3(0.9f, 0.9f, 1.0f);
  m_materials = {a, b, a};
}

void ShadedSpheres::Shade(uint32_t n, const float4* a_normals, float4* a_out) { kernel1D_Shade(n, a_normals, a_out); }

void ShadedSpheres::kernel1D_Shade(uint32_t n, const float4* a_normals, float4* a_out)
{
  for (uint32_t i = 0; i < n; i++)
  {
    const float3 normal = normalize(to_float3(a_normals[i]));
    const uint32_t id = uint32_t(a_normals[i].w) % uint32_t(m_materials.size());
    const IMaterial* material = m_materials[id].get();  // a local pointer to the element, called through
    const float3 next = m_materials[(id + 1) % uint32_t(m_materials.size())]->Shade(normal, m_light);
    a_out[i] = to_float4(material->Shade(normal, m_light), next.x + next.z + m_materials_tags + m_materials_objects + m_materials_Lambert + m_materials_Mirror +
                         m_materials_Shade);
  }
}
