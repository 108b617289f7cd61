// The class data after every translation unit: the megakernels' merged code and buffers, the members
// kernels use, and the layout of the class data block the shaders read.

#include "generate/GeneratedNames.h"
#include "analyse/AnalysisContext.h"
#include "analyse/Composition.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

namespace {

// A megakernel runs its kernels' thread functions: it needs their structs, constants, helpers
// (composed code included, so after composition), buffers and images.
static void MergeMegakernelCode(ClassModel& model) {
  for (auto& mk : model.megakernels) {
    std::vector<std::string> functions = mk.functionList;  // the thread loop's own helpers first
    auto addUnique = [](auto& list, const auto& x) {
      if (std::find(list.begin(), list.end(), x) == list.end()) list.push_back(x);
    };
    for (auto& name : mk.megakernelCalls) {
      auto k = std::find_if(model.kernels.begin(), model.kernels.end(), [&](const Kernel& x) { return x.name == name; });
      if (k == model.kernels.end()) continue;
      for (auto& chunk : k->structList)
        if (std::none_of(mk.structList.begin(), mk.structList.end(), [&](const GlslDecl& x) { return x.name == chunk.name; }))
          mk.structList.push_back(chunk);
      for (auto& x : k->constantList) addUnique(mk.constantList, x);
      for (auto& x : k->functionList) addUnique(functions, x);
      addUnique(functions, k->glslBody);
      for (auto& v : k->memberVectors) addUnique(mk.memberVectors, v);
      for (auto& ib : k->images) {
        auto same = std::find_if(mk.images.begin(), mk.images.end(), [&](const ImageBinding& x) { return x.member == ib.member && x.use == ib.use; });
        if (same == mk.images.end()) mk.images.push_back(ib);
        else { same->loaded |= ib.loaded; same->stored |= ib.stored; }
      }
      for (auto& pair : k->samplePairs) addUnique(mk.samplePairs, pair);
      for (auto& array : k->textureArrays) addUnique(mk.textureArrays, array);
      mk.composedCalls.insert(k->composedCalls.begin(), k->composedCalls.end());
      mk.bufferReferences |= k->bufferReferences;
      mk.atomics |= k->atomics;
      mk.scalarReferences |= k->scalarReferences;
    }
    std::sort(mk.memberVectors.begin(), mk.memberVectors.end());
    mk.functionList = functions;
  }
}

// The 4-vector the class data holds an element of an array of 3-vectors as (vec3[9] -> float4),
// whatever the C++ spells the element (a typedef of float3 too).
std::string PaddedElementType(const std::string& glslType) {
  const char kind = glslType[0];
  return kind == 'i' ? "LiteMath::int4" : kind == 'u' ? "LiteMath::uint4" : "LiteMath::float4";
}

}  // namespace

void FinishModel(ClassModel& model) {
  MergeMegakernelCode(model);
  // The class-data block: plain members kernels use, then sizes of member vectors.
  // Ordered by alignment so that the C++ mirror with alignas() has the std430 offsets.
  std::vector<BlockField> fields;
  for (auto& m : model.members)
    if (m.kind == MemberKind::Plain && m.inClassData && (m.usedByKernels || m.hostExpr == m.name))
      fields.push_back({m.name, m.padded3 ? PaddedElementType(m.glslType) : m.cppType, m.glslType, m.std430Align, m.hostExpr, ""});
  for (auto& m : model.members) {
    if (!m.usedByKernels || m.kind != MemberKind::Vector) continue;
    fields.push_back({generated::SizeField(m.name), "uint32_t", "uint", 4, "", ""});
    fields.push_back({generated::CapacityField(m.name), "uint32_t", "uint", 4, "", ""});
  }
  for (auto& m : model.members) {
    if (!m.usedByKernels || m.kind != MemberKind::Image) continue;
    fields.push_back({generated::ImageSizeField(m.name, "width"), "uint32_t", "uint", 4, "", m.hostExpr + ".width()"});
    fields.push_back({generated::ImageSizeField(m.name, "height"), "uint32_t", "uint", 4, "", m.hostExpr + ".height()"});
  }
  for (auto& m : model.members)
    if (m.usedByKernels && m.kind == MemberKind::TextureArray) fields.push_back({generated::SizeField(m.name), "uint32_t", "uint", 4, "", m.singleTexture ? std::string("1u") : "uint32_t(" + m.hostExpr + ".size())"});
  // Virtual functions: where each vector's tags and each implementation's objects are on the device.
  for (auto& v : model.virtuals) {
    fields.push_back({generated::VirtualTagsField(v.member), "uint64_t", "uvec2", 8, "", generated::kVirtualObjects + "." + v.member + "_tags.Address()"});
    fields.push_back({generated::SizeField(v.member), "uint32_t", "uint", 4, "", "uint32_t(" + v.hostExpr + ".size())"});
    if (model.virtualLevel == 1) fields.push_back({generated::VirtualSlotsField(v.member), "uint64_t", "uvec2", 8, "", generated::kVirtualObjects + "." + v.member + "_objects.Address()"});
    for (auto& impl : v.impls)
      if (model.virtualLevel >= 2)
        fields.push_back({generated::VirtualClassField(v.member, impl.name), "uint64_t", "uvec2", 8, "", generated::kVirtualObjects + "." + v.member + "_" + impl.name + ".Address()"});
  }
  std::stable_sort(fields.begin(), fields.end(), [](const BlockField& a, const BlockField& b) { return a.std430Align > b.std430Align; });
  if (fields.empty()) fields.push_back({"dummy", "uint32_t", "uint", 4, "", ""});  // a block needs a member
  model.classData = fields;
}

}  // namespace crossrt::engine
