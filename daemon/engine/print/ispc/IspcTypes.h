// ISPC's names of the GPU's types (GlslTypes.h spells them as GLSL does): LiteMath.isph's vectors
// and matrices, and the structs of objects reached through virtual calls. The analysis and the
// ISPC backend's generator ask them too.
#pragma once
#include <string>

namespace crossrt::engine {

// The ISPC name of a GLSL type name: LiteMath's (vec3 -> float3, uvec2 -> uint2, mat4 -> float4x4),
// the scalars and structs as they are; arrays keep their dimensions.
std::string IspcTypeName(const std::string& glslType);
// The ISPC struct of the data of a class reached through virtual calls: its qualified name with '_'
// for '::' and "_Data" (litept::Lambert -> litept_Lambert_Data). ISPC's header drops namespaces, and
// two classes of one name from two namespaces may meet in one program.
std::string IspcObjectStruct(const std::string& qualifiedName);

}  // namespace crossrt::engine
