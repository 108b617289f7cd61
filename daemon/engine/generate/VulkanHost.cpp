// The host code's data for the templates: per control function its ...Cmd recording (Vulkan) and
// its body (CPU), per Vulkan kernel its pipeline, bindings and dispatch, and the buffers and images
// the Vulkan class holds.
#include "generate/GeneratedNames.h"
#include "generate/VulkanHost.h"
#include "generate/CodeGenSupport.h"
#include "generate/CodeGen.h"
#include "print/KernelPrinter.h"

#include <fstream>
#include <set>
#include <stdexcept>

namespace crossrt::engine {

Data ControlsData(const ClassModel& model) {
  Data controls = List();
  // Pipelines specialised to what CommitDeviceData() found: a user's own call of a control function's
  // ...Cmd must not record with pipelines not made yet, or made for other values.
  const bool virtuals = ClassConstantCount(model) > 0, members = !SpecializedMembers(model).empty();
  std::string guard;
  if (virtuals || members) {
    const std::string what = std::string(virtuals ? "the classes the objects hold" : "") + (virtuals && members ? " and " : "") +
                             (members ? "the CRT_SPECIALIZE members' values" : "");
    guard = "  // The pipelines are made by CommitDeviceData() for " + what + ".\n"
            "  if (!crt_deviceDataCommitted" + std::string(members ? " || crt_SpecializedMembersChanged()" : "") + ")\n"
            "    throw crossrt::Error(\"" + model.generatedName + "::%sCmd: call CommitDeviceData() first: the pipelines are made for " + what + "\");\n";
  }
  for (auto& c : model.controls) {
    Data x;
    x.set("name", c.name);
    x.set("paramsDecl", c.paramsDecl);
    x.set("hasParams", !c.paramsDecl.empty());
    x.set("argsForward", c.argsForward);
    x.set("constQualifier", c.isConst ? " const" : "");
    x.set("notVirtual", !c.isVirtual);
    std::string body = IndentTail(c.vulkanCmdBody, "");
    if (!guard.empty() && body.rfind("{\n", 0) == 0) {
      std::string g = guard;
      g.replace(g.find("%s"), 2, c.name);
      body.insert(2, g);
    }
    x.set("cmdBody", body);
    x.set("hostTail", c.hasHostTail);
    x.set("synchronizes", c.synchronizes);
    x.set("cpuBody", IndentTail(c.cpuBody, "  "));
    x.set("sourceFile", c.sourceFile);
    Data ptrs = List(), outs = List();
    std::string bindDecl, bindArgs;
    for (auto& p : c.params) {
      if (!p.isPointer || p.hostOnly) continue;  // host code alone uses a host-only pointer, as written
      Data y;
      y.set("name", p.name);
      y.set("control", c.name);
      y.set("pointeeCpp", p.pointeeCpp);
      y.set("sizeExpr", p.sizeExpr);
      ptrs.push_back(y);
      if (!p.isConst) outs.push_back(y);
      bindDecl += (bindDecl.empty() ? "" : ", ") + std::string("crossrt::BufferView a_") + p.name;
      bindArgs += (bindArgs.empty() ? "" : ", ") + std::string("crt_self->crt_argCopies.") + c.name + "_" + p.name + ".View()";
    }
    Data images = List(), outImages = List();
    for (auto& p : c.params) {
      if (!p.isImage) continue;
      Data y;
      y.set("name", p.name);
      y.set("control", c.name);
      y.set("texelCpp", p.pointeeCpp);
      y.set("vkFormat", p.vkFormat);
      images.push_back(y);
      if (!p.isConst) outImages.push_back(y);
      bindDecl += (bindDecl.empty() ? "" : ", ") + std::string("crossrt::ImageView a_") + p.name;
      bindArgs += (bindArgs.empty() ? "" : ", ") + std::string("crossrt::ImageView(crt_self->crt_argCopies.") + c.name + "_" + p.name + ", " + p.name +
                  ".width(), " + p.name + ".height())";
    }
    x.set("pointerParams", ptrs);
    x.set("outputParams", outs);
    x.set("imageParams", images);
    x.set("outputImages", outImages);
    x.set("bindParamsDecl", bindDecl);
    // In ...Cmd the kernels use the bound buffers, so host pointers may go unused.
    std::string cmdDecl;
    for (auto& p : c.params) cmdDecl += (cmdDecl.empty() ? "" : ", ") + std::string(p.isPointer || p.isImage ? "[[maybe_unused]] " : "") + p.declText;
    x.set("cmdParamsDefinition", cmdDecl);
    x.set("bindArgs", bindArgs);
    // Member vectors written by any kernel this function calls are read back after it.
    Data written = List();
    std::set<std::string> seen;
    auto addWritten = [&](const std::string& v) {
      auto* m = FindMember(model, v);
      if (!m || !seen.insert(v).second) return;
      Data y;
      y.set("name", v);
      y.set("host", m->hostExpr);
      y.set("control", c.name);
      y.set("elemCppType", m->elemCppType);
      y.set("appended", m->appendedByKernels);
      y.set("inPlace", !m->appendedByKernels);  // read back at the size the host knows
      written.push_back(y);
    };
    for (auto& kn : c.kernelsCalled)
      for (auto& k : model.kernels)
        if (k.name == kn)
          for (auto& v : k.memberVectors)
            if (auto* m = FindMember(model, v); m && m->writtenByKernels) addWritten(v);
    for (auto& v : c.vectorsWritten) addWritten(v);  // by scans, fills, copies
    x.set("writtenVectors", written);
    // Image2D members stored by its kernels, or given to their non-const image parameters, are read
    // back after it, whole.
    Data writtenImages = List();
    std::set<std::string> seenImages;
    auto addImage = [&](const std::string& name) {
      auto* m = FindMember(model, name);
      if (!m || !seenImages.insert(name).second) return;
      Data y;
      y.set("name", name);
      y.set("host", m->hostExpr);
      y.set("control", c.name);
      y.set("texelCpp", m->elemCppType);
      writtenImages.push_back(y);
    };
    for (auto& kn : c.kernelsCalled)
      for (auto& k : model.kernels)
        if (k.name == kn)
          for (auto& ib : k.images)
            if (ib.stored && !ib.parameter) addImage(ib.member);
    for (auto& name : c.imagesWritten) addImage(name);
    x.set("writtenImages", writtenImages);
    auto localBuffers = [&](const std::vector<Control::LocalBuffer>& buffers) {
      Data list = List();
      for (auto& b : buffers) {
        Data y;
        y.set("buffer", b.buffer);
        y.set("cppType", b.cppType);
        y.set("local", b.local);
        y.set("control", c.name);
        list.push_back(y);
      }
      return list;
    };
    x.set("threadStates", localBuffers(c.threadStates));
    x.set("temporaries", localBuffers(c.temporaries));
    controls.push_back(x);
  }
  return controls;
}

Data VulkanKernelsData(const ClassModel& model, unsigned& indirectSlots) {
  Data kernels = List();
  indirectSlots = 0;
  for (const Kernel* kernel : VulkanKernels(model)) {
    const Kernel& k = *kernel;
    Data x;
    x.set("name", k.name);
    x.set("sourceFile", k.sourceFile);
    x.set("origin", k.megakernelOf.empty() ? model.className + "::" + k.name : "the thread loop of " + model.className + "::" + k.megakernelOf);
    std::string cmdParams;
    for (unsigned a = 0; k.rtv && a < k.dims; ++a) cmdParams += std::string(", uint32_t a_threads") + Axis(a);
    for (auto& p : k.params) {
      if (p.isThreadId) continue;
      cmdParams += ", " + (p.isPointer ? std::string("crossrt::BufferView") : p.isImage ? std::string("crossrt::ImageView") : p.cppType) + " " + p.name;
    }
    x.set("cmdParamsDecl", cmdParams);
    // Push constants: starts, counts, then scalar arguments (same order as the GLSL block).
    Data fields = List(), assign = List(), axes = List();
    auto field = [&](const std::string& align, const std::string& type, const std::string& name, const std::string& value) {
      Data f;
      f.set("align", align);
      f.set("cppType", type);
      f.set("name", name);
      fields.push_back(f);
      Data a;
      a.set("field", name);
      a.set("value", value);
      assign.push_back(a);
    };
    for (unsigned a = 0; a < k.dims; ++a) field("4", "int32_t", std::string("crt_start") + Axis(a), std::string("crt_start") + Axis(a));
    for (unsigned a = 0; a < k.dims; ++a) field("4", "uint32_t", std::string("crt_count") + Axis(a), std::string("crt_count") + Axis(a));
    for (auto& p : k.params) {
      if (p.isPointer || p.isThreadId) continue;
      if (p.isImage) {
        field("4", "uint32_t", generated::ImageSizeField(p.name, "width"), p.name + ".width()");
        field("4", "uint32_t", generated::ImageSizeField(p.name, "height"), p.name + ".height()");
        continue;
      }
      field(std::to_string(p.std430Align), p.valueCppType, KernelPrinter::SafeName(p.name), p.narrowed ? p.valueCppType + "(" + p.name + ")" : p.name);
    }
    x.set("pushFields", fields);
    // Image parameters it samples linearly: their format must allow it on this device.
    Data filterChecks = List();
    for (auto& [image, sampler] : k.paramSamplePairs) {
      Data f;
      f.set("image", image);
      f.set("sampler", sampler);
      filterChecks.push_back(f);
    }
    x.set("filterChecks", filterChecks);
    x.set("pushAssign", assign);
    for (unsigned a = 0; a < k.dims; ++a) {
      Data ax;
      ax.set("axis", Axis(a));
      if (k.rtv) {
        ax.set("startExpr", "0");
        ax.set("countExpr", std::string("a_threads") + Axis(a));
      } else {
        const Loop& loop = k.loops[k.dims - 1 - a];  // innermost loop is x
        ax.set("startExpr", "int(" + loop.startCpp + ")");
        // An indirect kernel's count is on the GPU; the host's copy of the vector is stale.
        ax.set("countExpr", k.indirectVector.empty() ? "uint32_t(std::max<int64_t>(0, int64_t(" + loop.countCpp + ")))"
                                                     : std::string("0u"));
      }
      axes.push_back(ax);
    }
    x.set("axes", axes);
    std::string empty;
    for (unsigned a = 0; a < k.dims; ++a) empty += (a ? " || " : "") + std::string("crt_count") + Axis(a) + " == 0";
    x.set("emptyTest", empty);
    // Kernels looping to the size of an appended vector: the GPU computes their groups.
    x.set("indirect", !k.indirectVector.empty());
    x.set("direct", k.indirectVector.empty());
    x.set("indirectVector", k.indirectVector);
    x.set("indirectSlot", std::to_string(indirectSlots));
    if (!k.indirectVector.empty()) ++indirectSlots;
    // What each variant binds, in the order its GLSL declares it: the class data, pointer arguments,
    // member vectors, reduction partials (storage buffers), images and samplers, then per array of
    // textures its infos and (sampled from buffers) its texels. The ray query variants bind their
    // own member vectors only, and the scene last (and so do the phases that do not trace: see
    // KernelVariant::ownVectors); the texture variants bind the arrays' sets.
    Data variants = List();
    const std::vector<KernelVariant> kinds = Variants(k);
    struct Bindings {
      std::string list, types, sets;
      unsigned buffers = 0;
      bool typed = false;  // bindings other than storage buffers
    };
    auto bindingsOf = [&](const KernelVariant& kind) {
      std::string list = generated::kClassData + ".View()", types = "VK_DESCRIPTOR_TYPE_STORAGE_BUFFER";
      unsigned buffers = 1;
      auto buffer = [&](const std::string& view) {
        list += ", " + view;
        types += ", VK_DESCRIPTOR_TYPE_STORAGE_BUFFER";
        ++buffers;
      };
      for (auto& p : k.params)
        if (p.isPointer) buffer(p.name);
      for (auto& v : kind.rayQuery || kind.ownVectors ? k.ownMemberVectors : k.memberVectors) buffer(generated::kVectorCopies + "." + v + ".View()");
      for (auto& r : k.reductions) buffer(generated::kPartials + "." + k.name + "_" + r.member + ".View()");
      bool typed = false;  // bindings other than storage buffers
      for (auto& ib : k.images) {
        const char* type = ib.use == ImageUse::Storage ? "VK_DESCRIPTOR_TYPE_STORAGE_IMAGE"
                           : ib.use == ImageUse::Texture ? "VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE" : "VK_DESCRIPTOR_TYPE_SAMPLER";
        types += std::string(", ") + type;
        list += std::string(", crossrt::Binding::") +
                (ib.use == ImageUse::Storage ? "StorageImage" : ib.use == ImageUse::Texture ? "SampledImage" : "SamplerOf") + "(" +
                (ib.parameter ? "" : generated::kImages + ".") + ib.member + ")";
        typed = true;
      }
      std::string sets;
      for (auto& a : k.textureArrays) {
        buffer(generated::kTextures + "." + a + "_info.View()");
        if (kind.textures) sets += (sets.empty() ? "&" : ", &") + generated::kTextures + "." + a;
        else buffer(generated::kTextures + "." + a + "_texels.View()");
      }
      if (kind.rayQuery) {
        types += ", VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR";
        list += ", crossrt::Binding::SceneOf(crt_scenes." + k.rayQueryHolder + ")";
        typed = true;
      }
      if (kind.leaves)
        for (const LeafTraversal* lt : LeafScenes(k)) {
          types += ", VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR";
          list += ", crossrt::Binding::SceneOf(crt_scenes." + lt->member + "_leaves)";
          typed = true;
        }
      return Bindings{list, types, sets, buffers, typed};
    };
    for (size_t vi = 0; vi < kinds.size(); ++vi) {
      const KernelVariant& kind = kinds[vi];
      const Bindings b = bindingsOf(kind);
      const bool typed = b.typed;
      const std::string& sets = b.sets;
      Data y;
      y.set("kernel", k.name);
      y.set("pipeline", k.name + kind.suffix);
      y.set("bindingList", b.list);
      y.set("bindingTypes", b.types);
      y.set("bindingCount", std::to_string(b.buffers));
      const bool rayGeneration = kind.RayGeneration();
      y.set("pushBuffers", !rayGeneration && !typed && !kind.textures);  // storage buffers only: the simple constructor
      y.set("pushBindings", !rayGeneration && (typed || kind.textures));
      y.set("rayTracingPipeline", rayGeneration);
      y.set("pipelineType", rayGeneration ? "crossrt::RayTracingPipeline" : "crossrt::ComputePipeline");
      // The pipeline's shaders (crossrt::RayTracingShaders): ray generation, miss shaders, hit
      // groups (intersection and closest hit), callables in executeCallableEXT's numbering.
      auto code = [&](const std::string& shader) { return "{" + model.symbolPrefix + "_" + shader + "_spv, " + model.symbolPrefix + "_" + shader + "_spvBytes}"; };
      std::string shaders;
      if (rayGeneration) {
        const std::string pad = "\n          ";
        shaders = "{" + code(k.name + kind.suffix) + ",";
        if (kind.leaves) {
          shaders += pad + "{  // miss shader i: a ray of the traces of leaf call i that meets no leaf";
          for (const LeafTraversal& lt : k.leaves) shaders += pad + "  " + code(lt.missShader) + ",";
          shaders += pad + "}," + pad + "{  // hit groups: per leaf call, one per class of its leaves";
          for (const LeafTraversal& lt : k.leaves)
            for (auto& c : lt.intersectionShaders) shaders += pad + "  {" + code(c) + ", " + code(lt.closestHitShader) + "},";
          shaders += pad + "}," + pad + "{}}";
        } else {
          shaders += pad + "{}," + pad + "{}," + pad + "{  // executeCallableEXT's numbering";
          for (auto& c : k.callables) shaders += pad + "  " + code(c) + ",";
          shaders += pad + "}}";
        }
      }
      y.set("rayTracingShaders", shaders);
      // A kernel with a ray generation variant records its launch in each branch: a trace or a dispatch.
      const bool traces = RunsCallables(k) || RunsLeafShaders(k);
      std::string launch;
      if (rayGeneration) launch = generated::kPipelines + "." + k.name + kind.suffix + ".TraceCmd(crt_cmd, " + LaunchSize(k) + ")";
      else if (traces) launch = DispatchExpr(k);
      if (launch.empty()) y.set("launch", false);  // the shared dispatch after the variants launches it
      else y.set("launch", launch);
      y.set("pushCall", typed ? "PushBindings" : "PushBuffers");
      y.set("textureSets", sets);
      y.set("hasTextureSets", !sets.empty());
      y.set("textureSetCount", std::to_string(k.textureArrays.size()));
      // Which devices can create it, and when the host records it.
      std::string needs, use, why;
      if (rayGeneration) {
        needs = "crt_ctx->hasRayTracingPipeline";
        use = "crt_useRayTracingPipelines";
        why = kind.callables ? "virtual calls as callable shaders, in a ray tracing pipeline"
                             : "the leaves of " + LeafDisplays(k) + " as intersection shaders, in a ray tracing pipeline";
      }
      if (kind.rayQuery) {
        needs = "crt_ctx->hasRayQuery";
        use = "crt_useRayTracingHardware";
        why = k.rayQueryHolder + "'s ray queries on the ray tracing hardware";
      }
      if (kind.textures) {
        needs += (needs.empty() ? "" : " && ") + std::string("crt_ctx->hasTextureArrays");
        use += (use.empty() ? "" : " && ") + std::string("crt_useTextureHardware");
        why += (why.empty() ? "" : ", ") + std::string("textures on the GPU's samplers");
      }
      y.set("conditional", !needs.empty());
      y.set("indentCreate", needs.empty() ? "" : "  ");
      y.set("needs", needs);
      y.set("why", why);
      y.set("comment", why.empty() ? "" : "  // " + why);
      // The host tries the variants in order; the last (every device's) is the `else`.
      const bool choice = kinds.size() > 1;
      y.set("choice", choice);
      y.set("head", !choice ? "" : vi == 0 ? "if (" + use + ")  // " + why : vi + 1 < kinds.size() ? "else if (" + use + ")  // " + why : "else");
      y.set("indent", choice ? "  " : "");
      variants.push_back(y);
    }
    x.set("variants", variants);
    // The one-thread shaders of the statements around the loop nest: the base variant's bindings.
    Data phases = List();
    for (const KernelVariant& v : Phases(k)) {
      Data y = variants.list_value().back();
      const Bindings b = bindingsOf(v);
      y.set("bindingList", b.list);
      y.set("bindingTypes", b.types);
      y.set("bindingCount", std::to_string(b.buffers));
      y.set("pipeline", k.name + v.suffix);
      y.set("conditional", false);
      y.set("indentCreate", "");
      y.set("comment", std::string("  // the statements ") + (v.phase == "Start" ? "before" : "after") + " the loop nest, on one thread");
      y.set("isStart", v.phase == "Start");
      y.set("isFinish", v.phase == "Finish");
      phases.push_back(y);
    }
    x.set("phases", phases);
    x.set("hasStart", !k.glslStart.empty());
    x.set("hasFinish", !k.glslFinish.empty());
    x.set("hasLoopEnds", !k.glslStart.empty() || !k.glslFinish.empty());
    x.set("startPipeline", k.name + "_Start");
    x.set("finishPipeline", k.name + "_Finish");
    Data reds = List();
    for (auto& r : k.reductions) {
      Data y;
      y.set("kernel", k.name);
      y.set("member", r.member);
      // The GPU writes an std430 array: a vec3 element takes 16 bytes, not sizeof(float3). An
      // array's elements (coefs[k] += x) take as many a workgroup as the array has.
      const std::string elements = ReductionElements(r);
      y.set("cppType", ReductionCppType(model, r) + (elements.empty() ? "" : "[" + elements + "]"));
      y.set("partialStride", std::to_string(Std430VectorStride(SplitArray(r.glslType).first)) + (elements.empty() ? "" : " * " + elements));
      y.set("groupCountExpr", GroupCountExpr(k));
      reds.push_back(y);
    }
    x.set("reduceBindingCount", std::to_string(1 + k.reductions.size()));
    x.set("reductions", reds);
    x.set("hasReductions", !k.reductions.empty());
    x.set("groupCountExpr", GroupCountExpr(k));
    x.set("dispatch", DispatchExpr(k));
    x.set("sharedDispatch", k.indirectVector.empty() && !RunsCallables(k) && !RunsLeafShaders(k));
    // Set only when there is a reason: an empty string still opens a section.
    if (const std::string why = k.callables.empty() ? "" : WhyNoCallables(k); !why.empty()) x.set("whyNoCallables", why);
    if (const std::string why = WhyNoLeafShaders(k); !why.empty()) x.set("whyNoLeafShaders", why);
    kernels.push_back(x);
  }
  return kernels;
}

Data ImagesData(const ClassModel& model, MemberKind kind) {
  Data images = List();
  for (auto& m : model.members) {
    if (m.kind != kind || !m.usedByKernels) continue;
    Data x;
    x.set("name", m.name);
    x.set("host", m.hostExpr);
    x.set("texelCpp", m.elemCppType);
    x.set("vkFormat", m.vkFormat);
    std::set<std::string> samplers;
    for (const Kernel* k : VulkanKernels(model))
      for (auto& [image, sampler] : k->samplePairs)
        if (image == m.name) samplers.insert(sampler);
    Data pairs = List();
    for (auto& sampler : samplers) {
      Data y;
      y.set("image", m.name);
      y.set("sampler", sampler);
      pairs.push_back(y);
    }
    x.set("samplePairs", pairs);
    images.push_back(x);
  }
  return images;
}

Data VectorsData(const ClassModel& model) {
  Data vectors = List();
  for (auto& m : model.members) {
    if (m.kind != MemberKind::Vector || !m.usedByKernels) continue;
    Data x;
    x.set("name", m.name);
    x.set("host", m.hostExpr);
    x.set("elemCppType", m.elemCppType);
    x.set("appended", m.appendedByKernels);
    // Composed data that only the translated traversal binds (ray query variants leave it out) is
    // not uploaded while the ray tracing hardware traces.
    const auto kernels = VulkanKernels(model);  // megakernels bind the traversal's data in either case
    const bool boundWithHardware = std::any_of(kernels.begin(), kernels.end(), [&](const Kernel* k) {
      const auto& bound = k->rayQueryHolder.empty() ? k->memberVectors : k->ownMemberVectors;
      return std::find(bound.begin(), bound.end(), m.name) != bound.end();
    });
    const bool traversalData = !m.composedFrom.empty() && !boundWithHardware &&
                               std::any_of(model.kernels.begin(), model.kernels.end(), [](const Kernel& k) { return !k.rayQueryHolder.empty(); });
    x.set("traversalData", traversalData);
    x.set("alwaysUploaded", !traversalData);
    vectors.push_back(x);
  }
  return vectors;
}

}  // namespace crossrt::engine
