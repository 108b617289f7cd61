// ISPC's names of the GPU's types (IspcTypes.h).
#include "print/ispc/IspcTypes.h"
#include "print/GlslTypes.h"

#include <map>

namespace crossrt::engine {

std::string IspcObjectStruct(const std::string& qualifiedName) {
  std::string name;
  for (size_t i = 0; i < qualifiedName.size(); ++i) {
    if (qualifiedName.compare(i, 2, "::") == 0) {
      name += '_';
      ++i;
    } else {
      name += qualifiedName[i];
    }
  }
  return name + "_Data";
}

std::string IspcTypeName(const std::string& glslType) {
  auto [base, dims] = SplitArray(glslType);
  static const std::map<std::string, std::string> names = {
      {"vec2", "float2"}, {"vec3", "float3"}, {"vec4", "float4"}, {"ivec2", "int2"}, {"ivec3", "int3"},
      {"ivec4", "int4"}, {"uvec2", "uint2"}, {"uvec3", "uint3"}, {"uvec4", "uint4"}, {"mat3", "float3x3"},
      {"mat4", "float4x4"}};
  auto it = names.find(base);
  return (it == names.end() ? base : it->second) + dims;
}

}  // namespace crossrt::engine
