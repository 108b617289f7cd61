// The generated class's header and host source, for the Vulkan class or the CPU class: the entry
// point that fills the templates of templates/ from the model.
#include "generate/CodeGenSupport.h"
#include "generate/GeneratedNames.h"
#include "generate/VulkanHost.h"
#include "generate/CodeGen.h"
#include "print/KernelPrinter.h"

#include <fstream>
#include <set>
#include <stdexcept>

namespace crossrt::engine {

std::map<std::string, std::string> GenerateHost(const ClassModel& model, const GenerateOptions& opt, bool vulkan) {
  std::map<std::string, std::string> files;
  Data d = Common(model, opt);
  d.set("controls", ControlsData(model));
  d.set("hasHostTails", std::any_of(model.controls.begin(), model.controls.end(), [](const Control& c) { return c.hasHostTail; }));
  d.set("hasVectorSwaps", std::any_of(model.controls.begin(), model.controls.end(), [](const Control& c) { return c.swapsVectors; }));
  d.set("hasSynchronize", std::any_of(model.controls.begin(), model.controls.end(), [](const Control& c) { return c.synchronizes; }));
  const Data vectors = VectorsData(model);
  d.set("vectors", vectors);
  d.set("hasVectors", !vectors.is_empty_list());
  if (vulkan) {
    d.set("usesScanner", model.usesScanner);
    d.set("usesSorter", model.usesSorter);
    Data images = ImagesData(model, MemberKind::Image), samplers = ImagesData(model, MemberKind::Sampler);
    d.set("images", images);
    d.set("samplers", samplers);
    Data textureArrays = List();
    for (auto& m : model.members) {
      if (m.kind != MemberKind::TextureArray || !m.usedByKernels) continue;
      Data x;
      x.set("name", m.name);
      x.set("host", m.hostExpr);
      x.set("vkFormat", m.vkFormat);
      // kernel_slicer's ICombinedImageSampler pointers: their texels as float4 textures, converted by CommitDeviceData()
      x.set("combined", m.combinedSamplers);
      x.set("textures", m.combinedSamplers ? "crt_" + m.name + "Textures" : m.hostExpr);
      x.set("count", m.singleTexture ? std::string("size_t(1)") : m.hostExpr + ".size()");
      textureArrays.push_back(x);
    }
    d.set("hasTextureArrays", !textureArrays.is_empty_list());
    d.set("textureArrays", textureArrays);
    d.set("hasImages", std::any_of(model.members.begin(), model.members.end(), [](const Member& m) {
      return m.usedByKernels && (m.kind == MemberKind::Image || m.kind == MemberKind::Sampler);
    }));
    // Whether anything on the GPU follows a host size (crt_VectorMembersResized has something to compare).
    d.set("hasResizables", !vectors.is_empty_list() || !images.is_empty_list() || !samplers.is_empty_list() ||
                               !textureArrays.is_empty_list() || !model.virtuals.empty());
    // The shaders of ray tracing pipelines besides the kernels' (virtual functions, level 3).
    Data stageShaders = List();
    const std::vector<const StageShader*> stages = ExecutedStageShaders(model);
    for (const StageShader* c : stages) {
      Data x;
      x.set("name", c->name);
      stageShaders.push_back(x);
    }
    d.set("stageShaders", stageShaders);
    d.set("hasRayTracingPipelines", !stages.empty());
    // Per vector whose elements are leaves of a traversal the hardware runs: its boxes' scene.
    Data leafScenes = List();
    std::set<std::string> leafMembers;
    for (const Kernel& k : model.kernels) {
      if (!RunsLeafShaders(k)) continue;
      for (const LeafTraversal* lt : LeafScenes(k)) {
        if (!leafMembers.insert(lt->member).second) continue;
        Data x;
        x.set("member", lt->member);
        x.set("host", lt->hostExpr);
        x.set("display", lt->display);
        x.set("interface", lt->interfaceName);
        auto vm = std::find_if(model.virtuals.begin(), model.virtuals.end(), [&](const VirtualMember& v) { return v.member == lt->member; });
        x.set("interfaceType", vm != model.virtuals.end() ? vm->interfaceCpp : lt->interfaceName);
        if (lt->leafBoxes.empty()) x.set("leafBoxes", false);
        else x.set("leafBoxes", lt->leafBoxes);
        leafScenes.push_back(x);
      }
    }
    d.set("leafScenes", leafScenes);
    d.set("hasLeafScenes", !leafScenes.is_empty_list());
    d.set("hasScenes", !leafScenes.is_empty_list() || std::any_of(model.kernels.begin(), model.kernels.end(), [](const Kernel& k) { return !k.rayQueryHolder.empty(); }));
    unsigned indirectSlots = 0;
    d.set("kernels", VulkanKernelsData(model, indirectSlots));
    d.set("indirectSlots", std::to_string(indirectSlots));
    d.set("hasIndirect", indirectSlots > 0);
    bool anyReductions = false;
    for (auto& k : model.kernels) anyReductions |= !k.reductions.empty();
    d.set("anyReductions", anyReductions);
    d.set("anyAtomics", std::any_of(model.kernels.begin(), model.kernels.end(), [](const Kernel& k) { return k.atomics; }));
    d.set("anyFloatAtomics", std::any_of(model.kernels.begin(), model.kernels.end(), [](const Kernel& k) { return k.floatAtomics; }));
    d.set("fenceConstantId", kFenceAtomicsConstantId);
    files[model.generatedName + ".h"] = Render(opt.templateDir + "/vulkan/class.h.mustache", d);
    files[model.generatedName + ".cpp"] = Render(opt.templateDir + "/vulkan/class.cpp.mustache", d);
    return files;
  }
  const std::string derived = model.generatedName;
  d.set("derived", derived);
  d.set("ispc", model.forIspc);
  d.set("whatRuns", model.forIspc ? "The loop nests of " + model.className + "'s kernels, and the thread loops\n"
                                        "// of its control functions (one or two thread ids), run here as ISPC (" + model.generatedName +
                                        "_kernels.ispc), on all CPU cores,\n// each in SIMD lanes (a kernel as the _CPU class runs it where "
                                        "that has been faster here);\n// everything else is inherited unchanged."
                                  : "The kernels of " + model.className + " run here on all\n// CPU cores (crossrt::ParallelFor); everything else is inherited unchanged.");
  if (model.forIspc) IspcHostData(model, d);
  Data kernels = List();
  for (auto& k : model.kernels) {
    if (k.rtv) continue;  // kernel_* bodies are inherited; their loops are parallelised in the control function
    Data x = CpuKernelData(k);
    // The _ISPC class keeps this form as the scalar way of a kernel (IspcHostData has the other).
    x.set("method", model.forIspc ? generated::ScalarMethod(k.name) : k.name);
    x.set("wayParam", model.forIspc ? KernelWayParam(k) : "");
    x.set("loopNest", IndentTail(k.cpuLoopNest, "    "));
    x.set("iterations", k.loops.empty() ? "1" : k.loops[0].countCpp);  // the outer loop's, which the cores share
    x.set("loopHead", k.cpuLoopHead);
    Data reds = List();
    for (auto& r : k.reductions) {
      // Each chunk reduces into a part of its own, crt_<name>Local (Kernels.cpp renames the target in
      // the loop nest), merged into crt_<name>Total: a copy of a member, or a reference to a local.
      // An array (its elements reduced: coefs[k] += x, bins[b] += x) element by element.
      const std::string count = ReductionElements(r);
      Data y;
      y.set("member", r.member);
      y.set("arraySize", count);
      y.set("whole", count.empty());
      y.set("ofMember", !r.local);
      y.set("part", generated::ReductionLocal(r.member));
      y.set("total", "crt_" + r.member + "Total");
      const bool minMax = r.op == ReduceOp::Min || r.op == ReduceOp::Max;
      y.set("fromTotal", minMax);
      y.set("op", r.op == ReduceOp::Min ? "crossrt::Minimum()" : r.op == ReduceOp::Max ? "crossrt::Maximum()" : "crossrt::Sum()");
      reds.push_back(y);
    }
    x.set("reductions", reds);
    x.set("hasReductions", !k.reductions.empty());
    kernels.push_back(x);
  }
  d.set("kernels", kernels);
  Data blockKernels = List();
  for (auto& bk : model.blockKernels) {
    Data x;
    x.set("name", bk.name);
    x.set("templateHead", bk.templateHead.empty() ? "" : bk.templateHead + "\n");
    x.set("paramsDecl", bk.paramsDecl);
    x.set("body", bk.body);
    x.set("sourceFile", bk.sourceFile);
    blockKernels.push_back(x);
  }
  d.set("blockKernels", blockKernels);
  Data copies = List();
  for (auto& lc : model.lockedCopies) {
    Data x;
    x.set("name", lc.name);
    x.set("sourceFile", lc.sourceFile);
    x.set("declaration", lc.declaration);
    x.set("definitionHead", lc.definitionHead);
    x.set("body", lc.body);
    x.set("keepOverloads", lc.keepOverloads);
    copies.push_back(x);
  }
  d.set("lockedCopies", copies);
  d.set("hasLockedCopies", !model.lockedCopies.empty());
  files[derived + ".h"] = Render(opt.templateDir + "/cpu/class.h.mustache", d);
  files[derived + ".cpp"] = Render(opt.templateDir + "/cpu/class.cpp.mustache", d);
  return files;
}

}  // namespace crossrt::engine
