// Turns a ClassModel into the generated files by rendering the text templates in templates/.
#include "CodeGen.h"

#include "Glsl.h"

#include <kainjow/mustache.hpp>

#include <cctype>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>

namespace crossrt::engine {
namespace {

using Data = kainjow::mustache::data;

Data List() { return Data(Data::type::list); }

// The shaders of a kernel, most specific first (the order the host tries them in): the variants for
// ray tracing hardware and for arrays of textures on the GPU's samplers, and the one every device runs.
struct KernelVariant {
  std::string suffix;  // "_Callables", "_Intersections", "_RayQuery_Textures", "_RayQuery", "_Textures" or ""
  bool rayQuery = false, textures = false, callables = false, leaves = false;
  // "Start" or "Finish": the one-thread shader of the statements before or after the loop nest,
  // with the bindings of the variant every device runs.
  std::string phase;
  bool RayGeneration() const { return callables || leaves; }  // a ray generation shader, not a compute shader
};

// The one-thread shaders of a kernel's statements before and after its loop nest (loop_start, loop_end).
std::vector<KernelVariant> Phases(const Kernel& k) {
  std::vector<KernelVariant> phases;
  if (!k.glslStart.empty()) phases.push_back({"_Start", false, false, false, false, "Start"});
  if (!k.glslFinish.empty()) phases.push_back({"_Finish", false, false, false, false, "Finish"});
  return phases;
}
// Virtual functions, level 3: a kernel whose virtual calls run as callable shaders, or whose composed
// traversal's leaves the ray tracing hardware finds, in a ray generation shader of its own. Not for
// kernels that need what only compute shaders have (shared memory for reductions, indirect dispatch)
// or other hardware variants, nor for megakernels: those keep the level-2 switch.
// Why a kernel cannot be a ray generation shader ("" when it can).
std::string WhyNoRayGeneration(const Kernel& k) {
  if (!k.reductions.empty()) return "its reductions need a compute shader's shared memory";
  if (!k.indirectVector.empty()) return "it is dispatched indirectly, which ray tracing pipelines are not here";
  if (!k.textureArrays.empty() || !k.rayQueryHolder.empty()) return "it has other hardware variants (arrays of textures or ray queries)";
  return "";  // megakernels have no callables or leaves of their own: MergeMegakernelCode keeps the kernels' switches
}

// Why a kernel with virtual calls at level 3 has no callables variant ("" when it has one).
std::string WhyNoCallables(const Kernel& k) {
  const std::string why = WhyNoRayGeneration(k);
  return !why.empty() || k.composedCalls.empty() ? why : "it calls composed code";
}

bool RunsCallables(const Kernel& k) { return !k.callables.empty() && WhyNoCallables(k).empty(); }
bool RunsLeafShaders(const Kernel& k) { return !k.leaves.empty() && WhyNoRayGeneration(k).empty(); }

// Why a kernel whose composed traversal calls a virtual function per leaf keeps that loop in software.
std::string WhyNoLeafShaders(const Kernel& k) {
  return !k.whyNoLeafShaders.empty() ? k.whyNoLeafShaders : k.leaves.empty() ? "" : WhyNoRayGeneration(k);
}

// The vectors whose leaves a kernel's traces find, once each, in the traces' order: one
// acceleration structure each.
std::vector<const LeafTraversal*> LeafScenes(const Kernel& k) {
  std::vector<const LeafTraversal*> out;
  for (const LeafTraversal& lt : k.leaves)
    if (std::none_of(out.begin(), out.end(), [&](const LeafTraversal* x) { return x->member == lt.member; })) out.push_back(&lt);
  return out;
}

// "a, b and c"
std::string Listed(const std::vector<std::string>& items) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i == 0 ? "" : i + 1 == items.size() ? " and " : ", ") + items[i];
  return out;
}

// The vectors whose leaves a kernel's traces find: "m_scene->m_shapes and m_scene->m_lights".
std::string LeafDisplays(const Kernel& k) {
  std::vector<std::string> displays;
  for (const LeafTraversal* lt : LeafScenes(k)) displays.push_back(lt->display);
  return Listed(displays);
}

// The shaders of ray tracing pipelines besides the kernels' that some kernel's ray generation
// variant executes: callables, then intersection, closest-hit and miss shaders, in the model's order.
std::vector<const StageShader*> ExecutedStageShaders(const ClassModel& model) {
  std::set<std::string> executed;
  for (const Kernel& k : model.kernels) {
    if (RunsCallables(k)) executed.insert(k.callables.begin(), k.callables.end());
    if (RunsLeafShaders(k))
      for (const LeafTraversal& lt : k.leaves) {
        executed.insert(lt.intersectionShaders.begin(), lt.intersectionShaders.end());
        executed.insert(lt.closestHitShader);
        executed.insert(lt.missShader);
      }
  }
  std::vector<const StageShader*> out;
  for (const std::vector<StageShader>* list : {&model.callables, &model.leafShaders})
    for (const StageShader& c : *list)
      if (executed.count(c.name)) out.push_back(&c);
  return out;
}

std::vector<KernelVariant> Variants(const Kernel& k) {
  std::vector<KernelVariant> variants;
  if (RunsCallables(k)) variants.push_back({"_Callables", false, false, true, false, ""});
  if (RunsLeafShaders(k)) variants.push_back({"_Intersections", false, false, false, true, ""});
  for (bool rayQuery : {true, false})
    for (bool textures : {true, false})
      if ((!rayQuery || !k.rayQueryHolder.empty()) && (!textures || !k.textureArrays.empty()))
        variants.push_back({std::string(rayQuery ? "_RayQuery" : "") + (textures ? "_Textures" : ""), rayQuery, textures, false, false, ""});
  return variants;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read template '" + path + "'");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// Sections that render nothing leave blank lines: keep at most one in a row, and none right
// after an opening brace.
std::string TidyBlankLines(const std::string& text) {
  std::string out;
  std::istringstream lines(text);
  std::string line, previous = "x";
  while (std::getline(lines, line)) {
    bool blank = line.find_first_not_of(" \t") == std::string::npos;
    bool afterBrace = !previous.empty() && previous.back() == '{';
    if (blank && (previous.empty() || afterBrace)) continue;
    out += (blank ? "" : line) + "\n";
    previous = blank ? "" : line;
  }
  return out;
}

// A line holding only a section tag ({{#x}}, {{^x}}, {{/x}}) renders nothing, not an empty line
// (mustache's "standalone" rule, which the library does not apply to skipped sections): the tag
// moves to the start of the next line. Before a blank line it stays, so that the library's own
// rule removes the tag's line and the blank line is kept (TidyBlankLines merges any doubles).
std::string JoinStandaloneTags(const std::string& text) {
  static const std::regex standalone(R"(^[ \t]*(\{\{[#^/][^}]*\}\})[ \t]*$)");
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::string out;
  std::smatch m;
  for (size_t i = 0; i < lines.size(); ++i) {
    const bool nextBlank = i + 1 >= lines.size() || lines[i + 1].find_first_not_of(" \t") == std::string::npos;
    if (std::regex_match(lines[i], m, standalone) && !nextBlank) out += m[1].str();
    else out += lines[i] + "\n";
  }
  return out;
}

std::string Render(const std::string& templatePath, const Data& data) {
  kainjow::mustache::mustache tmpl(JoinStandaloneTags(ReadFile(templatePath)));
  if (!tmpl.is_valid()) throw std::runtime_error(templatePath + ": " + tmpl.error_message());
  tmpl.set_custom_escape([](const std::string& s) { return s; });  // code, not HTML
  std::string out = tmpl.render(data);
  if (!tmpl.is_valid()) throw std::runtime_error(templatePath + ": " + tmpl.error_message());
  return TidyBlankLines(out);
}

// Indents every line but the first (which the template already indents).
std::string IndentTail(const std::string& text, const std::string& pad) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '\n' && i + 1 < text.size() && text[i + 1] != '\n') out += pad;
  }
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

// The specialization constant that switches the fences of crossrt atomics (crt_fenceAtomics). The
// runtime names it crossrt::kFenceAtomicsConstantId; generated host code static_asserts they agree.
const char* const kFenceAtomicsConstantId = "1700";

const char* Axis(unsigned a) { return a == 0 ? "X" : a == 1 ? "Y" : "Z"; }
const char* GlAxis(unsigned a) { return a == 0 ? "x" : a == 1 ? "y" : "z"; }

// What the Vulkan class dispatches: the kernels, then the megakernels of thread loops.
std::vector<const Kernel*> VulkanKernels(const ClassModel& model) {
  std::vector<const Kernel*> all;
  for (auto& k : model.kernels) all.push_back(&k);
  for (auto& k : model.megakernels) all.push_back(&k);
  return all;
}

// Workgroup shape by dimension count: 256 threads each, so reductions see the same group size.
struct GroupShape { unsigned x, y, z; };
GroupShape Shape(const Kernel& k) {
  static const GroupShape shapes[3] = {{256, 1, 1}, {16, 16, 1}, {8, 8, 4}};
  return shapes[k.dims - 1];
}

std::string Combine(ReduceOp op, const std::string& a, const std::string& b) {
  if (op == ReduceOp::Min) return "min(" + a + ", " + b + ")";
  if (op == ReduceOp::Max) return "max(" + a + ", " + b + ")";
  return a + " + " + b;  // Sub accumulates negative terms, so partials add up
}

std::string GroupCountExpr(const Kernel& k) {
  GroupShape s = Shape(k);
  if (k.dims == 1) return "crossrt::GroupCount1D(crt_countX, " + std::to_string(s.x) + ")";
  auto groups = [](const char* count, unsigned size) {
    return "((" + std::string(count) + " + " + std::to_string(size - 1) + ") / " + std::to_string(size) + ")";
  };
  std::string e = groups("crt_countX", s.x) + " * " + groups("crt_countY", s.y);
  return k.dims == 3 ? e + " * " + groups("crt_countZ", s.z) : e;
}

std::string DispatchExpr(const Kernel& k) {
  GroupShape s = Shape(k);
  if (k.dims == 1) return "crossrt::Dispatch1D(a_cmd, crt_countX, " + std::to_string(s.x) + ")";
  if (k.dims == 2) return "crossrt::Dispatch2D(a_cmd, crt_countX, crt_countY, " + std::to_string(s.x) + ", " + std::to_string(s.y) + ")";
  return "crossrt::Dispatch3D(a_cmd, crt_countX, crt_countY, crt_countZ, " + std::to_string(s.x) + ", " + std::to_string(s.y) + ", " + std::to_string(s.z) + ")";
}

// The launch of a kernel's ray generation variant: a thread per kernel thread. 1D counts go in
// rows of 65536, within every device's launch width (maxComputeWorkGroupCount[0] x group size).
std::string LaunchSize(const Kernel& k) {
  if (k.dims == 1) return "std::min<uint32_t>(crt_countX, 65536u), (crt_countX + 65535u) / 65536u, 1";
  if (k.dims == 2) return "crt_countX, crt_countY, 1";
  return "crt_countX, crt_countY, crt_countZ";
}

std::string ReductionCppType(const ClassModel& model, const Reduction& r) {
  if (!r.cppType.empty()) return r.cppType;
  auto* m = FindMember(model, r.member);
  return m ? m->cppType : "float";
}

Data ClassDataList(const ClassModel& model) {
  Data list = List();
  for (auto& f : model.classData) {
    Data d;
    auto [base, dims] = SplitArray(f.glslType);
    d.set("name", f.name);
    d.set("host", f.hostExpr.empty() ? f.name : f.hostExpr);
    d.set("cppType", f.cppType);
    d.set("arraySuffix", dims);
    d.set("align", std::to_string(f.std430Align));
    d.set("decl", base + " " + f.name + dims);
    auto* m = FindMember(model, f.name);
    d.set("isPlain", m != nullptr);
    d.set("computed", !f.assignExpr.empty());
    d.set("assignExpr", f.assignExpr);
    d.set("written", m != nullptr && m->writtenByKernels);
    list.push_back(d);
  }
  return list;
}

Data Common(const ClassModel& model, const GenerateOptions& opt) {
  Data d;
  d.set("className", model.className);
  d.set("namespaceName", model.namespaceName);
  d.set("hasNamespace", !model.namespaceName.empty());
  d.set("headerName", opt.headerName);
  d.set("headerInclude", opt.headerInclude);
  d.set("commitOverride", model.declaresCommitDeviceData ? " override" : "");
  d.set("timeOverride", model.declaresGetExecutionTime ? " override" : "");
  d.set("virtualDestructor", model.virtualDestructor);
  d.set("plainDestructor", !model.virtualDestructor);
  Data ctors = List();
  for (auto& c : model.constructors) {
    Data x;
    x.set("params", c.paramsDecl);
    x.set("args", c.argsForward);
    x.set("hasParams", !c.paramsDecl.empty());
    ctors.push_back(x);
  }
  d.set("constructors", ctors);
  d.set("classData", ClassDataList(model));
  bool writtenPlain = false;
  for (auto& m : model.members) writtenPlain |= m.kind == MemberKind::Plain && m.inClassData && m.writtenByKernels;
  d.set("hasWrittenPlain", writtenPlain);
  std::string usings;
  for (auto& i : model.sourceIncludes) usings += i + "\n";
  for (auto& u : model.usingDecls) usings += u + "\n";
  for (auto& decl : model.sourceDecls) usings += "\n" + decl + "\n";
  d.set("usingDecls", usings);
  d.set("hasUsingDecls", !usings.empty());
  d.set("hasMegakernels", !model.megakernels.empty());
  d.set("hasTemporaries", std::any_of(model.controls.begin(), model.controls.end(), [](const Control& c) { return !c.temporaries.empty(); }));
  d.set("defaultExecutionMode", model.megakernelByDefault ? "Megakernel" : "Wavefront");
  Data comps = List();
  for (auto& c : model.compositions) {
    if (c.implHeader.empty()) continue;
    Data x;
    x.set("holder", c.holder);
    x.set("interface", c.interfaceName);
    x.set("impl", c.implName);
    x.set("implInclude", opt.includeSpelling ? opt.includeSpelling(c.implHeader) : c.implHeader);
    comps.push_back(x);
  }
  d.set("compositions", comps);
  // ISceneObject members whose ray queries kernels may also answer on ray tracing hardware.
  Data rayQueryScenes = List();
  for (auto& c : model.compositions) {
    const bool traced = std::any_of(model.kernels.begin(), model.kernels.end(), [&](const Kernel& k) { return k.rayQueryHolder == c.holder; });
    if (c.implHeader.empty() || !traced) continue;
    Data x;
    x.set("holder", c.holder);
    x.set("impl", c.implName);
    rayQueryScenes.push_back(x);
  }
  d.set("rayQueryScenes", rayQueryScenes);
  d.set("hasRayQuery", !rayQueryScenes.is_empty_list());
  // Virtual functions: the implementations' data mirrors and the regrouping of the objects.
  Data virtuals = List(), implIncludes = List();
  std::set<std::string> headers, mirrored;
  for (auto& v : model.virtuals) {
    Data x;
    x.set("member", v.member);
    x.set("host", v.hostExpr);
    x.set("display", v.display);
    x.set("interface", v.interfaceName);
    std::string names;
    Data impls = List();
    for (size_t t = 0; t < v.impls.size(); ++t) {
      const VirtualImpl& vi = v.impls[t];
      names += (t ? ", " : "") + vi.name;
      Data y;
      y.set("impl", vi.name);
      y.set("member", v.member);
      y.set("typeIndex", std::to_string(t));
      y.set("first", t == 0);
      y.set("mirror", mirrored.insert(vi.name).second);  // one mirror per class, whichever vectors hold it
      Data fields = List();
      for (auto& f : vi.fields) {
        Data z;
        z.set("name", f.name);
        z.set("cppType", f.cppType);
        z.set("arraySuffix", SplitArray(f.glslType).second);
        fields.push_back(z);
      }
      y.set("fields", fields);
      y.set("layout", vi.scalarLayout ? "scalar" : "std430");
      impls.push_back(y);
      if (vi.header != model.headerFile && headers.insert(vi.header).second) {
        Data h;
        h.set("include", opt.includeSpelling ? opt.includeSpelling(vi.header) : vi.header);
        h.set("interface", v.interfaceName);
        implIncludes.push_back(h);
      }
    }
    x.set("impls", impls);
    x.set("implNames", names);
    x.set("level1", model.virtualLevel == 1);
    x.set("level2", model.virtualLevel >= 2);  // level 3 keeps the objects as level 2 does
    x.set("slotBytes", std::to_string(v.slotBytes));
    // Its elements are leaves the ray tracing hardware finds: their boxes are committed with it.
    x.set("leaves", std::any_of(model.kernels.begin(), model.kernels.end(), [&](const Kernel& k) {
            return RunsLeafShaders(k) && std::any_of(k.leaves.begin(), k.leaves.end(), [&](const LeafTraversal& lt) { return lt.member == v.member; });
          }));
    virtuals.push_back(x);
  }
  d.set("virtuals", virtuals);
  d.set("hasVirtuals", !model.virtuals.empty());
  d.set("virtualIncludes", implIncludes);
  return d;
}

// ---- GLSL ------------------------------------------------------------------

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

// The structs and constants of `chunks` that `used` (code kept) mentions, directly or through a
// kept chunk; order is kept. Chunks come dependencies first, so one pass from the back suffices.
std::vector<std::string> KeepMentioned(const std::vector<std::string>& chunks, std::string used, const std::regex& nameOf) {
  std::vector<bool> keep(chunks.size(), false);
  for (size_t i = chunks.size(); i-- > 0;) {
    std::smatch m;
    if (!std::regex_search(chunks[i], m, nameOf) || !MentionsWord(used, m[1].str())) continue;
    keep[i] = true;
    used += chunks[i];
  }
  std::vector<std::string> kept;
  for (size_t i = 0; i < chunks.size(); ++i)
    if (keep[i]) kept.push_back(chunks[i]);
  return kept;
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
  d.set("common", !hardware && first);
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
  const std::vector<std::string>& memberVectors = hardwareRayQuery ? k.ownMemberVectors : k.memberVectors;
  std::vector<std::string> functionList = k.functionList, structList = k.structList, constantList = k.constantList;
  if (callables) {
    functionList = k.callableFunctionList;
    structList = k.callableStructList;
  }
  if (kind.leaves) {
    functionList = k.leafFunctionList;
    structList = k.leafStructList;
  }
  if (hardwareRayQuery) {
    functionList = k.ownFunctionList;
    functionList.insert(functionList.begin(), RayQueryFunctions(k.rayQueryHolder, k.composedCalls, opt));
    std::string used = k.glslBody;
    for (auto& f : functionList) used += f;
    for (auto& p : k.params) used += " " + p.glslType;
    for (auto& v : memberVectors)
      if (auto* m = FindMember(model, v)) used += " " + m->glslType;
    // Structs, and the buffer reference types of virtual calls (layout(buffer_reference, ...) buffer T).
    static const std::regex structName(R"(^(?:struct|layout\(buffer_reference[^)]*\) readonly buffer) (\w+))"), constantName(R"(^const \w+ (\w+))");
    constantList = KeepMentioned(k.constantList, used, constantName);
    for (auto& c : constantList) used += c;
    structList = KeepMentioned(k.structList, used, structName);
  }
  std::string structs;
  for (auto& x : structList) structs += x + "\n";
  if (!k.textureArrays.empty())
    structs += "// A texture of an array as the host describes it (crossrt::TextureInfo): its texels' place in the\n"
               "// texel buffer, its size, its sampler's address modes and filter, its border colour.\n"
               "struct crt_TextureInfo\n{\n  uint offset;\n  uint width;\n  uint height;\n  uint mode;  // addressU | addressV << 2 | linear << 4\n"
               "  vec4 border;\n};\n\n";
  d.set("kernelStructs", structs);
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
    b.set("blockName", name + "Buffer");
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
    b.set("blockName", v + "Buffer");
    b.set("type", m ? m->glslType : "float");
    b.set("name", v);
    b.set("comment", m && !m->composedFrom.empty() ? "composed: std::vector " + m->composedFrom : "member std::vector " + v);
    buffers.push_back(b);
  }
  Data reductions = List();
  for (auto& r : k.reductions) {
    Data b;
    b.set("layout", "std430");
    b.set("binding", std::to_string(binding++));
    b.set("access", r.local ? "" : "writeonly ");  // a local's total is read back after the nest
    b.set("blockName", r.member + "PartialsBlock");
    b.set("type", r.glslType);
    b.set("name", r.member + "Partials");
    b.set("comment", "per-workgroup partial results of the reduction of " + std::string(r.local ? "local " : "") + r.member);
    buffers.push_back(b);
    Data x;
    x.set("type", r.glslType);
    x.set("member", r.member);
    x.set("identity", r.identity);
    x.set("combineGroup", Combine(r.op, r.member + "Group", r.member + "Shared[s]"));
    x.set("subgroupOp", r.op == ReduceOp::Min ? "subgroupMin" : r.op == ReduceOp::Max ? "subgroupMax" : "subgroupAdd");
    reductions.push_back(x);
  }
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
    const std::string at = "layout(binding = " + std::to_string(binding++);
    Data x;
    if (ib.use == ImageUse::Storage) {
      std::string access = !ib.stored ? "readonly " : !ib.loaded ? "writeonly " : "";
      x.set("decl", at + ", " + format + ") uniform " + access + prefix + "image2D " + name);
      x.set("comment", what + ": texels " + (ib.loaded && ib.stored ? "loaded and stored" : ib.loaded ? "loaded" : "stored"));
    } else if (ib.use == ImageUse::Texture) {
      x.set("decl", at + ") uniform " + prefix + "texture2D " + ib.member + "_texture");
      x.set("comment", what + ": sampled");
    } else {
      x.set("decl", at + ") uniform sampler " + ib.member);
      x.set("comment", "member LiteImage::Sampler " + ib.member);
    }
    images.push_back(x);
  }
  // Arrays of textures: each texture's size and sampler, and either its texels or its descriptor.
  for (size_t i = 0; i < k.textureArrays.size(); ++i) {
    auto* m = FindMember(model, k.textureArrays[i]);
    const std::string& a = k.textureArrays[i];
    const std::string cppType = "std::vector<LiteImage::Texture2D<" + (m ? m->elemCppType : std::string("?")) + ">>";
    Data x;
    x.set("decl", "layout(std430, binding = " + std::to_string(binding++) + ") readonly buffer " + a + "InfoBuffer { crt_TextureInfo " + a + "_info[]; }");
    x.set("comment", "member " + cppType + " " + a + ": its textures' sizes and samplers");
    images.push_back(x);
    Data y;
    if (hardwareTextures) {
      y.set("decl", "layout(set = " + std::to_string(1 + i) + ", binding = 0) uniform sampler2D " + a + "[]");
      y.set("comment", "its textures, with their samplers");
    } else {
      y.set("decl", "layout(std430, binding = " + std::to_string(binding++) + ") readonly buffer " + a + "TexelBuffer { " + (m ? m->glslType : "vec4") + " " + a + "_texels[]; }");
      y.set("comment", "their texels, one texture after the other");
    }
    images.push_back(y);
  }
  if (hardwareRayQuery) {
    Data x;
    x.set("decl", "layout(binding = " + std::to_string(binding++) + ") uniform accelerationStructureEXT " + k.rayQueryHolder + "_scene");
    x.set("comment", "the scene " + k.rayQueryHolder + " holds, built for the ray tracing hardware");
    images.push_back(x);
  }
  if (kind.leaves)
    for (const LeafTraversal* lt : LeafScenes(k)) {
      Data x;
      x.set("decl", "layout(binding = " + std::to_string(binding++) + ") uniform accelerationStructureEXT " + lt->member + "_leaves");
      x.set("comment", "a box per element of " + lt->display + ", for the ray tracing hardware");
      images.push_back(x);
    }
  d.set("images", images);
  d.set("scalarLayout", scalarAny || k.scalarReferences);
  d.set("bufferReferences", k.bufferReferences);
  d.set("buffers", buffers);
  d.set("reductions", kind.phase.empty() ? reductions : List());  // a phase binds the partials, but has no part in them
  d.set("hasReductions", kind.phase.empty() && !k.reductions.empty());
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
      s.set("decl", "uint " + p.name + "_width");
      push.push_back(s);
      s.set("decl", "uint " + p.name + "_height");
      push.push_back(s);
      continue;
    }
    auto [base, dims] = SplitArray(p.glslType);
    s.set("decl", base + " " + p.glslName + dims);
    push.push_back(s);
  }
  d.set("pushConstants", push);
  std::string helpers;
  for (auto& x : constantList) helpers += x;
  if (!constantList.empty()) helpers += "\n";
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
    std::string gid = k.dims == 1 ? "int(threadId)" : "int(" + invocation + "." + GlAxis(a) + ")";
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
  d.set("threadIndex", k.dims == 1 ? "threadId"
                       : k.dims == 2 ? g + ".x + crt_countX * " + g + ".y"
                                     : g + ".x + crt_countX * (" + g + ".y + crt_countY * " + g + ".z)");
  for (unsigned a = 0; a < k.dims; ++a)
    active += (a ? " && " : "") + invocation + "." + GlAxis(a) + " < crt_count" + Axis(a);
  d.set("threadArgs", threadArgs);
  d.set("activeTest", active);
  // A kernel dispatched indirectly runs to the count the GPU holds (capped at the vector's capacity).
  const std::string& v = k.indirectVector;
  d.set("countLimit", v.empty() ? std::string("crt_countX") : "min(" + v + "_size, " + v + "_capacity)");
  d.set("indirect", !v.empty());
  d.set("indirectVector", v);
  return Render(opt.templateDir + "/glsl/kernel.comp.mustache", d);
}

// Virtual functions, level 3: a shader of a ray tracing pipeline other than the ray generation
// shader (a callable, intersection, closest-hit or miss shader).
std::string StageGlsl(const ClassModel& model, const StageShader& c, const GenerateOptions& opt) {
  Data d = Common(model, opt);
  d.set("name", c.name);
  d.set("origin", c.origin);
  d.set("description", c.description);
  d.set("scalarLayout", c.scalarLayout);
  d.set("bufferReferences", c.stage == "rcall" || c.stage == "rint");  // they reach the objects through them
  d.set("classStructs", c.stage == "rmiss" ? std::string() : model.glslClassStructs);
  d.set("hasClassData", c.classData);
  d.set("constants", c.constants);
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
    Data x;
    x.set("type", r.glslType);
    x.set("member", r.member);
    x.set("identity", r.identity);
    x.set("binding", std::to_string(binding++));
    x.set("combineShared", Combine(r.op, r.member + "Shared[local]", r.member + "Shared[local + stride]"));
    x.set("combinePartial", Combine(r.op, r.member + "Local", r.member + "Partials[i]"));
    x.set("combineMember", Combine(r.op, r.member, r.member + "Shared[0]"));
    x.set("local", r.local);  // its total goes to element 0 of its partials, for <kernel>_Finish
    x.set("access", r.local ? "" : "readonly ");
    reductions.push_back(x);
  }
  d.set("reductions", reductions);
  return Render(opt.templateDir + "/glsl/reduce.comp.mustache", d);
}

// ---- host code ---------------------------------------------------------------

Data ControlsData(const ClassModel& model) {
  Data controls = List();
  for (auto& c : model.controls) {
    Data x;
    x.set("name", c.name);
    x.set("paramsDecl", c.paramsDecl);
    x.set("hasParams", !c.paramsDecl.empty());
    x.set("argsForward", c.argsForward);
    x.set("constQualifier", c.isConst ? " const" : "");
    x.set("notVirtual", !c.isVirtual);
    x.set("cmdBody", IndentTail(c.vulkanCmdBody, ""));
    x.set("cpuBody", IndentTail(c.cpuBody, "  "));
    x.set("sourceFile", c.sourceFile);
    Data ptrs = List(), outs = List();
    std::string bindDecl, bindArgs;
    for (auto& p : c.params) {
      if (!p.isPointer) continue;
      Data y;
      y.set("name", p.name);
      y.set("control", c.name);
      y.set("pointeeCpp", p.pointeeCpp);
      y.set("sizeExpr", p.sizeExpr);
      ptrs.push_back(y);
      if (!p.isConst) outs.push_back(y);
      bindDecl += (bindDecl.empty() ? "" : ", ") + std::string("crossrt::BufferView a_") + p.name;
      bindArgs += (bindArgs.empty() ? "" : ", ") + std::string("crt_self->m_args.") + c.name + "_" + p.name + ".View()";
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
      bindArgs += (bindArgs.empty() ? "" : ", ") + std::string("crossrt::ImageView(crt_self->m_args.") + c.name + "_" + p.name + ", " + p.name +
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
        field("4", "uint32_t", p.name + "_width", p.name + ".width()");
        field("4", "uint32_t", p.name + "_height", p.name + ".height()");
        continue;
      }
      field(std::to_string(p.std430Align), p.valueCppType, GlslPrinter::SafeName(p.name), p.narrowed ? p.valueCppType + "(" + p.name + ")" : p.name);
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
    // own member vectors only, and the scene last; the texture variants bind the arrays' sets.
    Data variants = List();
    const std::vector<KernelVariant> kinds = Variants(k);
    for (size_t vi = 0; vi < kinds.size(); ++vi) {
      const KernelVariant& kind = kinds[vi];
      std::string list = "m_classDataBuffer.View()", types = "VK_DESCRIPTOR_TYPE_STORAGE_BUFFER";
      unsigned buffers = 1;
      auto buffer = [&](const std::string& view) {
        list += ", " + view;
        types += ", VK_DESCRIPTOR_TYPE_STORAGE_BUFFER";
        ++buffers;
      };
      for (auto& p : k.params)
        if (p.isPointer) buffer(p.name);
      for (auto& v : kind.rayQuery ? k.ownMemberVectors : k.memberVectors) buffer("m_vdata." + v + ".View()");
      for (auto& r : k.reductions) buffer("m_partials." + k.name + "_" + r.member + ".View()");
      bool typed = false;  // bindings other than storage buffers
      for (auto& ib : k.images) {
        const char* type = ib.use == ImageUse::Storage ? "VK_DESCRIPTOR_TYPE_STORAGE_IMAGE"
                           : ib.use == ImageUse::Texture ? "VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE" : "VK_DESCRIPTOR_TYPE_SAMPLER";
        types += std::string(", ") + type;
        list += std::string(", crossrt::Binding::") +
                (ib.use == ImageUse::Storage ? "StorageImage" : ib.use == ImageUse::Texture ? "SampledImage" : "SamplerOf") + "(" +
                (ib.parameter ? "" : "m_images.") + ib.member + ")";
        typed = true;
      }
      std::string sets;
      for (auto& a : k.textureArrays) {
        buffer("m_textures." + a + "_info.View()");
        if (kind.textures) sets += (sets.empty() ? "&m_textures." : ", &m_textures.") + a;
        else buffer("m_textures." + a + "_texels.View()");
      }
      if (kind.rayQuery) {
        types += ", VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR";
        list += ", crossrt::Binding::SceneOf(m_scenes." + k.rayQueryHolder + ")";
        typed = true;
      }
      if (kind.leaves)
        for (const LeafTraversal* lt : LeafScenes(k)) {
          types += ", VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR";
          list += ", crossrt::Binding::SceneOf(m_scenes." + lt->member + "_leaves)";
          typed = true;
        }
      Data y;
      y.set("kernel", k.name);
      y.set("pipeline", k.name + kind.suffix);
      y.set("bindingList", list);
      y.set("bindingTypes", types);
      y.set("bindingCount", std::to_string(buffers));
      const bool rayGeneration = kind.RayGeneration();
      y.set("pushBuffers", !rayGeneration && !typed && !kind.textures);  // storage buffers only: the simple constructor
      y.set("pushBindings", !rayGeneration && (typed || kind.textures));
      y.set("rayTracingPipeline", rayGeneration);
      y.set("pipelineType", rayGeneration ? "crossrt::RayTracingPipeline" : "crossrt::ComputePipeline");
      // The pipeline's shaders (crossrt::RayTracingShaders): ray generation, miss shaders, hit
      // groups (intersection and closest hit), callables in executeCallableEXT's numbering.
      auto code = [&](const std::string& shader) { return "{" + model.className + "_" + shader + "_spv, " + model.className + "_" + shader + "_spvBytes}"; };
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
      if (rayGeneration) launch = "m_pipelines." + k.name + kind.suffix + ".TraceCmd(a_cmd, " + LaunchSize(k) + ")";
      else if (traces) launch = DispatchExpr(k);
      y.set("launch", launch);
      y.set("pushCall", typed ? "PushBindings" : "PushBuffers");
      y.set("textureSets", sets);
      y.set("hasTextureSets", !sets.empty());
      y.set("textureSetCount", std::to_string(k.textureArrays.size()));
      // Which devices can create it, and when the host records it.
      std::string needs, use, why;
      if (rayGeneration) {
        needs = "m_ctx->hasRayTracingPipeline";
        use = "m_useRayTracingPipelines";
        why = kind.callables ? "virtual calls as callable shaders, in a ray tracing pipeline"
                             : "the leaves of " + LeafDisplays(k) + " as intersection shaders, in a ray tracing pipeline";
      }
      if (kind.rayQuery) {
        needs = "m_ctx->hasRayQuery";
        use = "m_useRayTracingHardware";
        why = k.rayQueryHolder + "'s ray queries on the ray tracing hardware";
      }
      if (kind.textures) {
        needs += (needs.empty() ? "" : " && ") + std::string("m_ctx->hasTextureArrays");
        use += (use.empty() ? "" : " && ") + std::string("m_useTextureHardware");
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
      y.set("cppType", ReductionCppType(model, r));
      // The GPU writes an std430 array: a vec3 element takes 16 bytes, not sizeof(float3).
      y.set("partialStride", std::to_string(Std430VectorStride(r.glslType)));
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

// Image2D and LiteImage::Sampler members kernels use, and the (image, sampler) pairs they sample.
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

std::string ScalarOmpOp(ReduceOp op) { return op == ReduceOp::Min ? "min" : op == ReduceOp::Max ? "max" : "+"; }

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

std::map<std::string, std::string> GenerateHost(const ClassModel& model, const GenerateOptions& opt, bool vulkan) {
  std::map<std::string, std::string> files;
  Data d = Common(model, opt);
  d.set("controls", ControlsData(model));
  d.set("vectors", VectorsData(model));
  if (vulkan) {
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
      textureArrays.push_back(x);
    }
    d.set("hasTextureArrays", !textureArrays.is_empty_list());
    d.set("textureArrays", textureArrays);
    d.set("hasImages", std::any_of(model.members.begin(), model.members.end(), [](const Member& m) {
      return m.usedByKernels && (m.kind == MemberKind::Image || m.kind == MemberKind::Sampler);
    }));
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
    files[model.className + "_Vulkan.h"] = Render(opt.templateDir + "/vulkan/class.h.mustache", d);
    files[model.className + "_Vulkan.cpp"] = Render(opt.templateDir + "/vulkan/class.cpp.mustache", d);
    return files;
  }
  Data kernels = List(), ompReductions = List();
  std::set<std::string> declared;
  for (auto& k : model.kernels) {
    if (k.rtv) continue;  // kernel_* bodies are inherited; their loops are parallelised in the control function
    Data x;
    x.set("name", k.name);
    x.set("sourceFile", k.sourceFile);
    x.set("paramsDecl", k.cppParamsDecl);
    x.set("preamble", IndentTail(k.cpuPreamble, "  "));
    x.set("hasPreamble", !k.cpuPreamble.empty());
    x.set("postamble", IndentTail(k.cpuPostamble, "  "));
    x.set("hasPostamble", !k.cpuPostamble.empty());
    x.set("loopNest", IndentTail(k.cpuLoopNest, "  "));
    // Dynamic chunks: iterations may cost very different amounts (a ray that hits against one that
    // misses). With static halves PrimaryRays_CPU cast the bunny's rays at 0.57-0.63x of Embree,
    // with chunks of 1024 at 0.71-0.75x (bench_lbvh, 2 threads). 2D kernels hand out rows.
    x.set("schedule", k.dims == 1 ? "dynamic, 1024" : "dynamic, 1");
    std::string clauses;
    Data reds = List();
    for (auto& r : k.reductions) {
      // A member is reduced through a local copy (<member>Local); a local is reduced itself.
      const std::string reduced = r.local ? r.member : r.member + "Local";
      if (!r.local) {
        Data y;
        y.set("member", r.member);
        reds.push_back(y);
      }
      std::string cppType = ReductionCppType(model, r);
      bool scalar = r.glslType == "float" || r.glslType == "int" || r.glslType == "uint";
      if (scalar) {
        clauses += " reduction(" + ScalarOmpOp(r.op) + ":" + reduced + ")";
        continue;
      }
      // LiteMath vectors need a declared reduction.
      std::string opName = std::string(r.op == ReduceOp::Min ? "min" : r.op == ReduceOp::Max ? "max" : "add");
      std::string name = "crossrt_" + opName + "_" + SplitArray(r.glslType).first;
      clauses += " reduction(" + name + ":" + reduced + ")";
      if (declared.insert(name).second) {
        Data o;
        o.set("name", name);
        o.set("cppType", cppType);
        o.set("combine", r.op == ReduceOp::Min ? "LiteMath::min(omp_out, omp_in)" : r.op == ReduceOp::Max ? "LiteMath::max(omp_out, omp_in)" : "omp_out + omp_in");
        o.set("init", r.op == ReduceOp::Min || r.op == ReduceOp::Max ? "omp_orig" : cppType + "()");
        ompReductions.push_back(o);
      }
    }
    x.set("reductions", reds);
    x.set("ompClauses", clauses);
    kernels.push_back(x);
  }
  d.set("kernels", kernels);
  d.set("ompReductions", ompReductions);
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
  files[model.className + "_CPU.h"] = Render(opt.templateDir + "/cpu/class.h.mustache", d);
  files[model.className + "_CPU.cpp"] = Render(opt.templateDir + "/cpu/class.cpp.mustache", d);
  return files;
}

}  // namespace crossrt::engine
