// The shaders: each kernel's GLSL (and its variants for ray queries, arrays of textures, ray
// generation), reduction passes and stage shaders, rendered from templates/glsl. Takes the model;
// gives one ShaderSource per shader.
#include "generate/CodeGenSupport.h"
#include "generate/GeneratedNames.h"
#include "generate/CodeGen.h"
#include "print/KernelPrinter.h"

#include <cctype>
#include <fstream>
#include <set>
#include <stdexcept>

namespace crossrt::engine {

namespace {

// One binding of a kernel's images, textures or acceleration structures, for the `images` section
// of templates/glsl/kernel.comp.mustache: every kind's flag is set, so that none is looked up in the
// enclosing context.
Data Binding(unsigned binding, const std::string& name) {
  Data x;
  for (const char* kind : {"storageImage", "texture", "sampler", "textureSizes", "samplerArray", "texelBuffer", "accelerationStructure"})
    x.set(kind, false);
  x.set("binding", std::to_string(binding));
  x.set("name", name);
  return x;
}

// Whether a kernel's reductions start from an infinity (min or max over floats): its shaders then
// define CRT_INFINITY.
bool UsesInfinity(const Kernel& k) {
  return std::any_of(k.reductions.begin(), k.reductions.end(), [](const Reduction& r) {
    return (r.op == ReduceOp::Min || r.op == ReduceOp::Max) && r.glslType.find("ivec") == std::string::npos &&
           r.glslType.find("uvec") == std::string::npos && r.glslType != "int" && r.glslType != "uint";
  });
}

// ISceneObject's ray queries through `holder` on ray tracing hardware: what the <kernel>_RayQuery
// shader has in place of the composed implementation's traversal. The results follow the interface
// (CrossRT.h): a miss has ids 0xFFFFFFFF and t = tmax, barycentrics as Embree defines them (Vulkan's
// are the same), both sides of a triangle hit. Rays the interface says miss (non-finite, a zero
// direction, an empty interval) do so before any query, since Vulkan leaves such rays undefined.
std::string RayQueryFunctions(const std::string& holder, const std::set<std::pair<std::string, std::string>>& calls,
                              const GenerateOptions& opt) {
  Data d;
  d.set("holder", holder);
  d.set("nearestHit", calls.count({holder, "RayQuery_NearestHit"}) > 0);
  d.set("anyHit", calls.count({holder, "RayQuery_AnyHit"}) > 0);
  return Render(opt.templateDir + "/glsl/ray_query.glsl.mustache", d);
}

// Whether `name` occurs as a whole word in `text`.
bool MentionsWord(const std::string& text, const std::string& name) {
  for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1)) {
    auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    const size_t end = at + name.size();
    if ((at == 0 || !word(text[at - 1])) && (end >= text.size() || !word(text[end]))) return true;
  }
  return false;
}

// The structs and constants of `chunks` that `used` (code kept) mentions by the names they
// declare, directly or through a kept chunk; order is kept. Chunks come dependencies first, so one pass from the back suffices.
std::vector<GlslDecl> KeepMentioned(const std::vector<GlslDecl>& chunks, std::string used) {
  std::vector<bool> keep(chunks.size(), false);
  for (size_t i = chunks.size(); i-- > 0;) {
    if (chunks[i].name.empty() || !MentionsWord(used, chunks[i].name)) continue;
    keep[i] = true;
    used += chunks[i].text;
  }
  std::vector<GlslDecl> kept;
  for (size_t i = 0; i < chunks.size(); ++i)
    if (keep[i]) kept.push_back(chunks[i]);
  return kept;
}

// The CRT_SPECIALIZE members that `used` (a shader's code) reads, as specialization constants.
// The host makes every pipeline with their values (crt_pipelineConstants), so the defaults here are
// never what a kernel reads.
std::string SpecializedConstants(const ClassModel& model, const std::string& used) {
  std::string out;
  const std::vector<const Member*> members = SpecializedMembers(model);
  for (size_t i = 0; i < members.size(); ++i) {
    const Member& m = *members[i];
    const std::string name = generated::SpecializedConstant(m.name);
    if (!MentionsWord(used, name)) continue;
    const std::string zero = m.glslType == "bool" ? "false" : m.glslType == "uint" ? "0u" : m.glslType == "float" ? "0.0" : "0";
    out += "// " + (m.composedFrom.empty() ? model.className + "::" + m.name : m.composedFrom) +
           " (CRT_SPECIALIZE): its value when the pipeline was made, which the driver folds into the code\n";
    out += "layout(constant_id = " + std::to_string(kClassConstantIdBase + ClassConstantCount(model) + i) + ") const " + m.glslType + " " + name +
           " = " + zero + ";\n";
  }
  return out;
}

// The functions kernels call on an array of textures (<array>_sample, ...): with the GPU's
// samplers (hardware) or over buffers, as LiteImage samples (the helpers they share come once).
std::string TextureArrayFunctions(const Member& array, bool hardware, bool first, const GenerateOptions& opt) {
  Data d;
  d.set("member", array.name);
  d.set("texel", array.glslType);
  d.set("border", array.glslType == "vec4" ? "t.border" : "t.border.x");
  d.set("channel", array.glslType == "vec4" ? "" : ".x");
  d.set("hardware", hardware);
  d.set("software", !hardware);
  d.set("common", first);  // both sample far-away and non-finite coordinates as LiteImage does
  return Render(opt.templateDir + "/glsl/texture_array.glsl.mustache", d);
}

// A shader of a kernel, in variant `v`: rayQuery traces with ray queries (Kernel::rayQueryHolder),
// textures samples arrays of textures with the GPU's samplers (Kernel::textureArrays), callables is
// the ray generation shader whose virtual calls execute callable shaders (Kernel::callables), and
// leaves the one whose composed traversal traces its leaves on the hardware (Kernel::leaves).
std::string KernelGlsl(const ClassModel& model, const Kernel& k, const GenerateOptions& opt, const KernelVariant& kind) {
  const bool hardwareRayQuery = kind.rayQuery, hardwareTextures = kind.textures, callables = kind.callables, rayGeneration = kind.RayGeneration();
  Data d = Common(model, opt);
  d.set("kernel", k.name);
  d.set("sourceFile", k.sourceFile);
  const GroupShape shape = kind.phase.empty() ? Shape(k) : GroupShape{1, 1, 1};
  d.set("groupX", std::to_string(shape.x));
  d.set("groupY", std::to_string(shape.y));
  d.set("groupZ", std::to_string(shape.z));
  d.set("shaderName", k.name + kind.suffix);
  d.set("hasPhase", !kind.phase.empty());
  d.set("phaseName", kind.phase);
  d.set("groupSize", std::to_string(shape.x * shape.y * shape.z));
  d.set("classStructs", model.glslClassStructs);
  d.set("rayQuery", hardwareRayQuery);
  d.set("textureHardware", hardwareTextures);
  d.set("rayGeneration", rayGeneration);
  d.set("compute", !rayGeneration);
  std::string variant;
  if (callables) variant = ": the variant for ray tracing pipelines, whose virtual calls execute a callable shader per class";
  if (kind.leaves) {
    std::vector<std::string> traversals;
    for (const LeafTraversal& lt : k.leaves)
      if (std::find(traversals.begin(), traversals.end(), lt.traversal) == traversals.end()) traversals.push_back(lt.traversal);
    variant = ": the variant for ray tracing pipelines, in which the hardware finds the leaves of " + Listed(traversals) +
              "\n// and an intersection shader per class of " + LeafDisplays(k) + " intersects them";
  }
  if (hardwareRayQuery) variant = ": the variant for ray tracing hardware (GL_EXT_ray_query)";
  if (!kind.phase.empty())
    variant = std::string(":\n// the statements ") + (kind.phase == "Start" ? "before" : "after") + " its loop nest, which one thread runs " +
              (kind.phase == "Start" ? "before" : "after") + " the nest's threads";
  if (hardwareTextures) variant += std::string(variant.empty() ? ": the variant" : ",") + " for arrays of textures on the GPU's samplers (descriptor indexing)";
  else if (!k.textureArrays.empty()) variant += std::string(variant.empty() ? ": the variant" : ",") + " sampling arrays of textures from buffers, on any device";
  d.set("variant", variant);
  std::string calls;
  for (auto& c : k.megakernelCalls) calls += (calls.empty() ? "" : ", ") + c;
  d.set("origin", k.megakernelOf.empty() ? model.className + "::" + k.name
                                         : "the thread loop of " + model.className + "::" + k.megakernelOf + ", as one megakernel running " + calls);
  // The ray query variant drops the composed implementation: its functions, buffers, and the
  // structs and constants only they used.
  const std::vector<std::string>& memberVectors = hardwareRayQuery || kind.ownVectors ? k.ownMemberVectors : k.memberVectors;
  std::vector<std::string> functionList = k.functionList;
  std::vector<GlslDecl> structList = k.structList, constantList = k.constantList;
  if (callables) {
    functionList = k.callableFunctionList;
    structList = k.callableStructList;
  }
  if (kind.leaves) {
    functionList = k.leafFunctionList;
    structList = k.leafStructList;
  }
  if (hardwareRayQuery || kind.ownVectors) {
    functionList = k.ownFunctionList;
    if (hardwareRayQuery) functionList.insert(functionList.begin(), RayQueryFunctions(k.rayQueryHolder, k.composedCalls, opt));
    std::string used = kind.phase == "Start" ? k.glslStart : kind.phase == "Finish" ? k.glslFinish : k.glslBody;
    for (auto& f : functionList) used += f;
    for (auto& p : k.params) used += " " + p.glslType;
    for (auto& v : memberVectors)
      if (auto* m = FindMember(model, v)) used += " " + m->glslType;
    // Constants, structs, and the buffer reference types of virtual calls, by the names they declare.
    constantList = KeepMentioned(k.constantList, used);
    for (auto& c : constantList) used += c.text;
    structList = KeepMentioned(k.structList, used);
  }
  std::string structs;
  for (auto& x : structList) structs += x.text + "\n";
  d.set("kernelStructs", structs);
  d.set("textureInfo", !k.textureArrays.empty());  // crt_TextureInfo, in the template
  for (size_t i = k.textureArrays.size(); i-- > 0;)
    if (auto* m = FindMember(model, k.textureArrays[i])) functionList.insert(functionList.begin(), TextureArrayFunctions(*m, hardwareTextures, i == 0, opt));
  // Atomics order the kernel's other writes for other threads (Atomics.h): the buffers it may
  // write are coherent, so that those writes are not held in a cache another thread misses.
  const std::string coherent = k.atomics ? "coherent " : "";
  d.set("atomics", k.atomics);
  d.set("floatAtomics", k.floatAtomics);
  d.set("fenceConstantId", kFenceAtomicsConstantId);
  d.set("classDataAccess", coherent);
  Data buffers = List();
  unsigned binding = 1;
  bool scalarAny = false;  // any buffer that needs GL_EXT_scalar_block_layout
  for (auto& p : k.params) {
    if (!p.isPointer) continue;
    Data b;
    b.set("layout", p.scalarLayout ? "scalar" : "std430");
    scalarAny |= p.scalarLayout;
    b.set("binding", std::to_string(binding++));
    b.set("access", p.isConstPointee ? "readonly " : coherent);
    // A per-thread value: main() loads this thread's element, passes it, and stores it back.
    const std::string name = p.threadState ? p.glslName + "PerThread" : p.glslName;
    b.set("blockName", generated::BlockName(name));
    b.set("type", p.glslType);
    b.set("name", name);
    b.set("comment", p.threadState ? "parameter '" + p.name + "': one value per thread, kept between the kernels of a thread loop"
                                   : k.megakernelOf.empty() ? "parameter '" + p.name + "'" : "parameter '" + p.name + "' of the kernels that name it so");
    buffers.push_back(b);
  }
  for (auto& v : memberVectors) {
    auto* m = FindMember(model, v);
    Data b;
    b.set("layout", m && m->scalarLayout ? "scalar" : "std430");
    scalarAny |= m && m->scalarLayout;
    b.set("binding", std::to_string(binding++));
    b.set("access", coherent);
    b.set("blockName", generated::BlockName(v));
    b.set("type", m ? m->glslType : "float");
    b.set("name", v);
    b.set("comment", m && !m->composedFrom.empty() ? "composed: std::vector " + m->composedFrom : "member std::vector " + v);
    buffers.push_back(b);
  }
  Data reductions = List();
  bool anyWhole = false;
  for (auto& r : k.reductions) {
    // An array's elements (coefs[k] += x, bins[b] += x): each thread an array, each workgroup a partial
    // result per element (partials[group * elements + element]).
    const std::string elements = ReductionElements(r), type = SplitArray(r.glslType).first;
    anyWhole |= elements.empty();
    Data b;
    b.set("layout", "std430");
    b.set("binding", std::to_string(binding++));
    b.set("access", r.local ? "" : "writeonly ");  // a local's total is read back after the nest
    b.set("blockName", generated::BlockName(r.member + "Partials"));  // crt_<member>PartialsBuffer
    b.set("type", type);
    b.set("name", generated::ReductionPartials(r.member));
    b.set("comment", "per-workgroup partial results of the reduction of " + std::string(r.local ? "local " : "") + r.member +
                         (elements.empty() ? "" : ", " + elements + " elements a workgroup"));
    buffers.push_back(b);
    Data x;
    x.set("type", type);
    x.set("member", r.member);
    x.set("identity", r.identity);
    x.set("whole", elements.empty());
    x.set("isArray", !elements.empty());
    x.set("elements", elements);
    const std::string group = generated::ReductionGroup(r.member), shared = generated::ReductionShared(r.member);
    x.set("combineGroup", Combine(r.op, group, shared + (elements.empty() ? "[s]" : "[crt_e * (" + std::to_string(shape.x * shape.y * shape.z) + " / 4) + s]")));
    x.set("subgroupOp", r.op == ReduceOp::Min ? "subgroupMin" : r.op == ReduceOp::Max ? "subgroupMax" : "subgroupAdd");
    reductions.push_back(x);
  }
  d.set("anyWholeReductions", anyWhole);
  // Images and samplers follow the buffers (the host pushes them in this order).
  Data images = List();
  for (auto& ib : k.images) {
    // A member's format, or a parameter's (named as the kernel's GLSL names it).
    std::string format, prefix, name = ib.member;
    if (auto* m = ib.parameter ? nullptr : FindMember(model, ib.member)) {
      format = m->imageFormat;
      prefix = m->imagePrefix;
    }
    for (auto& p : k.params)
      if (ib.parameter && p.isImage && p.name == ib.member) {
        format = p.imageFormat;
        prefix = p.imagePrefix;
        name = p.glslName;
      }
    const std::string what = (ib.parameter ? "parameter Image2D " : "member Image2D ") + ib.member;
    Data x = Binding(binding++, "");
    if (ib.use == ImageUse::Storage) {
      x.set("storageImage", true);
      x.set("format", format);
      x.set("access", std::string(!ib.stored ? "readonly " : !ib.loaded ? "writeonly " : ""));
      x.set("prefix", prefix);
      x.set("name", name);
      x.set("comment", what + ": texels " + (ib.loaded && ib.stored ? "loaded and stored" : ib.loaded ? "loaded" : "stored"));
    } else if (ib.use == ImageUse::Texture) {
      x.set("texture", true);
      x.set("prefix", prefix);
      x.set("name", generated::TextureName(ib.member));
      x.set("comment", what + ": sampled");
    } else {
      x.set("sampler", true);
      x.set("name", ib.member);
      x.set("comment", "member LiteImage::Sampler " + ib.member);
    }
    images.push_back(x);
  }
  // Arrays of textures: each texture's size and sampler, and either its texels or its descriptor.
  for (size_t i = 0; i < k.textureArrays.size(); ++i) {
    auto* m = FindMember(model, k.textureArrays[i]);
    const std::string& a = k.textureArrays[i];
    const bool combined = m && m->combinedSamplers;  // ICombinedImageSampler pointers: float4 textures
    const std::string cppType = combined ? m->cppType : "std::vector<LiteImage::Texture2D<" + (m ? m->elemCppType : std::string("?")) + ">>";
    Data x = Binding(binding++, a);
    x.set("textureSizes", true);
    x.set("comment", "member " + cppType + " " + a + (combined ? " (as float4 textures)" : "") + ": its textures' sizes and samplers");
    images.push_back(x);
    if (hardwareTextures) {
      Data y = Binding(0, a);
      y.set("samplerArray", true);
      y.set("set", std::to_string(1 + i));
      y.set("comment", std::string("its textures, with their samplers"));
      images.push_back(y);
    } else {
      Data y = Binding(binding++, a);
      y.set("texelBuffer", true);
      y.set("type", m ? m->glslType : std::string("vec4"));
      y.set("comment", std::string("their texels, one texture after the other"));
      images.push_back(y);
    }
  }
  if (hardwareRayQuery) {
    Data x = Binding(binding++, k.rayQueryHolder + "_scene");
    x.set("accelerationStructure", true);
    x.set("comment", "the scene " + k.rayQueryHolder + " holds, built for the ray tracing hardware");
    images.push_back(x);
  }
  if (kind.leaves)
    for (const LeafTraversal* lt : LeafScenes(k)) {
      Data x = Binding(binding++, lt->member + "_leaves");
      x.set("accelerationStructure", true);
      x.set("comment", "a box per element of " + lt->display + ", for the ray tracing hardware");
      images.push_back(x);
    }
  d.set("images", images);
  d.set("scalarLayout", scalarAny || k.scalarReferences);
  d.set("bufferReferences", k.bufferReferences);
  d.set("buffers", buffers);
  d.set("reductions", kind.phase.empty() ? reductions : List());  // a phase binds the partials, but has no part in them
  d.set("hasReductions", kind.phase.empty() && !k.reductions.empty());
  d.set("usesInfinity", UsesInfinity(k));
  Data push = List();
  for (unsigned a = 0; a < k.dims; ++a) {
    Data s;
    s.set("decl", std::string("int crt_start") + Axis(a));
    push.push_back(s);
  }
  for (unsigned a = 0; a < k.dims; ++a) {
    Data s;
    s.set("decl", std::string("uint crt_count") + Axis(a));
    push.push_back(s);
  }
  for (auto& p : k.params) {
    if (p.isPointer || p.isThreadId) continue;
    Data s;
    if (p.isImage) {  // its size, as the host image has it (an empty image's device copy has one texel)
      s.set("decl", "uint " + generated::ImageSizeField(p.name, "width"));
      push.push_back(s);
      s.set("decl", "uint " + generated::ImageSizeField(p.name, "height"));
      push.push_back(s);
      continue;
    }
    auto [base, dims] = SplitArray(p.glslType);
    s.set("decl", base + " " + p.glslName + dims);
    push.push_back(s);
  }
  d.set("pushConstants", push);
  std::string helpers;
  for (auto& x : constantList) helpers += x.text;
  if (!constantList.empty()) helpers += "\n";
  std::string code = kind.phase == "Start" ? k.glslStart : kind.phase == "Finish" ? k.glslFinish : k.glslBody;
  for (auto& x : functionList) code += x;
  if (const std::string specialized = SpecializedConstants(model, code); !specialized.empty()) helpers += specialized + "\n";
  for (auto& x : functionList) helpers += x + "\n";
  d.set("helpers", helpers);
  d.set("body", kind.phase == "Start" ? k.glslStart : kind.phase == "Finish" ? k.glslFinish : k.glslBody);
  d.set("dim1", k.dims == 1);
  d.set("dimN", k.dims != 1);
  // Arguments of the thread function: each thread id in the type its parameter or loop variable has.
  std::vector<std::string> idTypes;
  if (k.rtv) {
    for (auto& p : k.params)
      if (p.isThreadId) idTypes.push_back(p.glslType);
  } else {
    for (unsigned a = 0; a < k.dims; ++a) idTypes.push_back(k.loops[k.dims - 1 - a].glslType);  // x is the innermost loop
  }
  // RTV thread functions also take the per-thread values and the by-value arguments (push constants).
  std::string threadArgs, active;
  Data stateLoads = List(), stateStores = List();
  bool threadState = false;
  std::vector<std::string> ids;
  // A ray generation thread's id is its launch id: the launch spans the thread counts exactly.
  const std::string invocation = rayGeneration ? "gl_LaunchIDEXT" : "gl_GlobalInvocationID";
  for (size_t i = 0; i < k.threadAxes.size(); ++i) {
    unsigned a = k.threadAxes[i];
    std::string gid = k.dims == 1 ? "int(crt_threadId)" : "int(" + invocation + "." + GlAxis(a) + ")";
    ids.push_back(idTypes[i] + "(crt_start" + Axis(a) + " + " + gid + ")");
  }
  if (!k.rtv)
    for (auto& id : ids) threadArgs += (threadArgs.empty() ? "" : ", ") + id;
  for (size_t i = 0, id = 0; k.rtv && i < k.params.size(); ++i) {
    std::string arg;
    if (k.params[i].isThreadId) {
      arg = ids[id++];
    } else if (k.params[i].threadState) {
      const KernelParam& p = k.params[i];
      arg = p.glslName;
      Data load;
      load.set("text", p.glslType + " " + p.glslName + " = " + p.glslName + "PerThread[threadIndex];");
      stateLoads.push_back(load);
      threadState = true;
      if (!p.isConstPointee) {
        Data store;
        store.set("text", p.glslName + "PerThread[threadIndex] = " + p.glslName + ";");
        stateStores.push_back(store);
      }
    } else if (!k.params[i].isPointer && !k.params[i].isImage) {
      arg = k.params[i].glslName;
    } else {
      continue;
    }
    threadArgs += (threadArgs.empty() ? "" : ", ") + arg;
  }
  d.set("hasThreadState", threadState);
  d.set("noThreadState", !threadState);
  d.set("stateLoads", stateLoads);
  d.set("stateStores", stateStores);
  // The thread's element of per-thread buffers: threads in x, then rows, then slices.
  const std::string& g = invocation;
  d.set("threadIndex", k.dims == 1 ? "crt_threadId"
                       : k.dims == 2 ? g + ".x + crt_countX * " + g + ".y"
                                     : g + ".x + crt_countX * (" + g + ".y + crt_countY * " + g + ".z)");
  for (unsigned a = 0; a < k.dims; ++a)
    active += (a ? " && " : "") + invocation + "." + GlAxis(a) + " < crt_count" + Axis(a);
  d.set("threadArgs", threadArgs);
  d.set("activeTest", active);
  // A kernel dispatched indirectly runs to the count the GPU holds (capped at the vector's capacity).
  const std::string& v = k.indirectVector;
  d.set("countLimit", v.empty() ? std::string("crt_countX") : "min(" + generated::SizeField(v) + ", " + generated::CapacityField(v) + ")");
  d.set("indirect", !v.empty());
  d.set("indirectVector", v);
  return Render(opt.templateDir + "/glsl/kernel.comp.mustache", d);
}

// Virtual functions, level 3: a shader of a ray tracing pipeline other than the ray generation
// shader (a callable, intersection, closest-hit or miss shader).
std::string StageGlsl(const ClassModel& model, const StageShader& c, const GenerateOptions& opt) {
  Data d = Common(model, opt);
  // The traversal's buffers it reads, at the bindings its kernel gives them (KernelGlsl: the pointer
  // parameters from 1, then the member vectors).
  Data buffers = List();
  bool scalar = c.scalarLayout;
  auto k = std::find_if(model.kernels.begin(), model.kernels.end(), [&](const Kernel& x) { return x.name == c.kernel; });
  for (const std::string& v : c.buffers) {
    if (k == model.kernels.end()) break;
    auto at = std::find(k->memberVectors.begin(), k->memberVectors.end(), v);
    if (at == k->memberVectors.end()) continue;
    const Member* m = FindMember(model, v);
    const auto pointers = std::count_if(k->params.begin(), k->params.end(), [](const KernelParam& p) { return p.isPointer; });
    Data b;
    b.set("layout", m && m->scalarLayout ? "scalar" : "std430");
    scalar |= m && m->scalarLayout;
    b.set("binding", std::to_string(1 + pointers + (at - k->memberVectors.begin())));
    b.set("blockName", generated::BlockName(v));
    b.set("type", m ? m->glslType : "float");
    b.set("name", v);
    b.set("comment", m && !m->composedFrom.empty() ? "composed: std::vector " + m->composedFrom : "member std::vector " + v);
    buffers.push_back(b);
  }
  d.set("buffers", buffers);
  d.set("name", c.name);
  d.set("origin", c.origin);
  d.set("description", c.description);
  d.set("scalarLayout", scalar);
  d.set("bufferReferences", c.stage == "rcall" || c.stage == "rint");  // they reach the objects through them
  d.set("classStructs", c.stage == "rmiss" ? std::string() : model.glslClassStructs);
  d.set("hasClassData", c.classData);
  d.set("constants", c.constants + SpecializedConstants(model, c.functions + c.mainBody));
  d.set("structs", c.structs);
  d.set("functions", c.functions);
  d.set("mainBody", c.mainBody);
  return Render(opt.templateDir + "/glsl/stage.glsl.mustache", d);
}

std::string ReduceGlsl(const ClassModel& model, const Kernel& k, const GenerateOptions& opt) {
  Data d = Common(model, opt);
  d.set("kernel", k.name);
  d.set("sourceFile", k.sourceFile);
  d.set("groupSize", "256");  // the single workgroup folding the partial results
  d.set("classStructs", model.glslClassStructs);
  Data reductions = List();
  unsigned binding = 1;
  for (auto& r : k.reductions) {
    const std::string elements = ReductionElements(r);
    Data x;
    x.set("type", SplitArray(r.glslType).first);
    x.set("member", r.member);
    x.set("identity", r.identity);
    x.set("binding", std::to_string(binding++));
    x.set("whole", elements.empty());
    x.set("isArray", !elements.empty());  // an array's elements (coefs[k] += x, bins[b] += x), one after another
    x.set("elements", elements);
    const std::string shared = generated::ReductionShared(r.member);
    x.set("combineShared", Combine(r.op, shared + "[local]", shared + "[local + stride]"));
    x.set("combinePartial", Combine(r.op, generated::ReductionLocal(r.member),
                                    generated::ReductionPartials(r.member) + (elements.empty() ? "[i]" : "[i * " + elements + "u + crt_e]")));
    x.set("combineMember", Combine(r.op, r.member + (elements.empty() ? "" : "[crt_e]"), shared + "[0]"));
    x.set("local", r.local);  // its total goes to element 0 of its partials, for <kernel>_Finish
    x.set("access", r.local ? "" : "readonly ");
    reductions.push_back(x);
  }
  d.set("reductions", reductions);
  d.set("anyWholeReductions", std::any_of(k.reductions.begin(), k.reductions.end(), [](const Reduction& r) { return ReductionElements(r).empty(); }));
  d.set("usesInfinity", UsesInfinity(k));
  return Render(opt.templateDir + "/glsl/reduce.comp.mustache", d);
}

}  // namespace

std::vector<ShaderSource> GenerateShaders(const ClassModel& model, const GenerateOptions& opt) {
  std::vector<ShaderSource> shaders;
  for (const Kernel* kernel : VulkanKernels(model)) {
    const Kernel& k = *kernel;
    for (const KernelVariant& v : Variants(k))
      shaders.push_back({k.name + v.suffix, KernelGlsl(model, k, opt, v), v.RayGeneration() ? "rgen" : "comp"});
    for (const KernelVariant& v : Phases(k)) shaders.push_back({k.name + v.suffix, KernelGlsl(model, k, opt, v), "comp"});
    if (!k.reductions.empty()) shaders.push_back({k.name + "_Reduce", ReduceGlsl(model, k, opt)});
  }
  for (const StageShader* c : ExecutedStageShaders(model)) shaders.push_back({c->name, StageGlsl(model, *c, opt), c->stage});
  return shaders;
}

}  // namespace crossrt::engine
