// What the code generators share: rendering a template of templates/ from mustache data, the data
// every generated file gets (Common), a kernel's shader variants and its dispatch sizes.
#include "generate/CodeGenSupport.h"
#include "generate/CodeGen.h"
#include "print/KernelPrinter.h"
#include "print/ispc/IspcTypes.h"

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>

namespace crossrt::engine {

Data List() { return Data(Data::type::list); }

std::vector<KernelVariant> Phases(const Kernel& k) {
  // The composed implementation's GLSL names all begin with its holder's name.
  const std::string composed = k.rayQueryHolder + "_";
  auto traces = [&](const std::string& body) {
    if (body.find(composed) != std::string::npos) return true;
    return std::any_of(k.ownFunctionList.begin(), k.ownFunctionList.end(), [&](const std::string& f) { return f.find(composed) != std::string::npos; });
  };
  std::vector<KernelVariant> phases;
  if (!k.glslStart.empty()) phases.push_back({"_Start", false, false, false, false, "Start", !k.rayQueryHolder.empty() && !traces(k.glslStart)});
  if (!k.glslFinish.empty()) phases.push_back({"_Finish", false, false, false, false, "Finish", !k.rayQueryHolder.empty() && !traces(k.glslFinish)});
  return phases;
}

namespace {

// Virtual functions, level 3: a kernel whose virtual calls run as callable shaders, or whose composed
// traversal's leaves the ray tracing hardware finds, in a ray generation shader of its own. Not for
// kernels that need what only compute shaders have (shared memory for reductions, indirect dispatch)
// or ray queries (their own hardware variant), nor for megakernels: those keep the level-2 switch.
// Arrays of textures come along: every device with ray tracing pipelines samples them with its
// samplers (descriptor indexing), so the ray generation shader is also the kernel's _Textures form.
// Why a kernel cannot be a ray generation shader ("" when it can).
std::string WhyNoRayGeneration(const Kernel& k) {
  if (!k.reductions.empty()) return "its reductions need a compute shader's shared memory";
  if (!k.indirectVector.empty()) return "it is dispatched indirectly, which ray tracing pipelines are not here";
  if (!k.rayQueryHolder.empty()) return "it has a variant of its own for ray queries";
  return "";  // megakernels have no callables or leaves of their own: MergeMegakernelCode keeps the kernels' switches
}

}  // namespace

std::string WhyNoCallables(const Kernel& k) {
  const std::string why = WhyNoRayGeneration(k);
  return !why.empty() || k.composedCalls.empty() ? why : "it calls composed code";
}

bool RunsCallables(const Kernel& k) { return !k.callables.empty() && WhyNoCallables(k).empty(); }

bool RunsLeafShaders(const Kernel& k) { return !k.leaves.empty() && WhyNoRayGeneration(k).empty(); }

std::string WhyNoLeafShaders(const Kernel& k) {
  return !k.whyNoLeafShaders.empty() ? k.whyNoLeafShaders : k.leaves.empty() ? "" : WhyNoRayGeneration(k);
}

std::vector<const LeafTraversal*> LeafScenes(const Kernel& k) {
  std::vector<const LeafTraversal*> out;
  for (const LeafTraversal& lt : k.leaves)
    if (std::none_of(out.begin(), out.end(), [&](const LeafTraversal* x) { return x->member == lt.member; })) out.push_back(&lt);
  return out;
}

std::string Listed(const std::vector<std::string>& items) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i == 0 ? "" : i + 1 == items.size() ? " and " : ", ") + items[i];
  return out;
}

std::string LeafDisplays(const Kernel& k) {
  std::vector<std::string> displays;
  for (const LeafTraversal* lt : LeafScenes(k)) displays.push_back(lt->display);
  return Listed(displays);
}

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
  const bool textures = !k.textureArrays.empty();  // a ray generation shader samples them on the GPU's samplers
  const std::string samplers = textures ? "_Textures" : "";
  if (RunsCallables(k)) variants.push_back({"_Callables" + samplers, false, textures, true, false, ""});
  if (RunsLeafShaders(k)) variants.push_back({"_Intersections" + samplers, false, textures, false, true, ""});
  for (bool rayQuery : {true, false})
    for (bool textures : {true, false})
      if ((!rayQuery || !k.rayQueryHolder.empty()) && (!textures || !k.textureArrays.empty()))
        variants.push_back({std::string(rayQuery ? "_RayQuery" : "") + (textures ? "_Textures" : ""), rayQuery, textures, false, false, ""});
  return variants;
}

namespace {

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

}  // namespace

std::string Render(const std::string& templatePath, const Data& data) {
  kainjow::mustache::mustache tmpl(JoinStandaloneTags(ReadFile(templatePath)));
  if (!tmpl.is_valid()) throw std::runtime_error(templatePath + ": " + tmpl.error_message());
  tmpl.set_custom_escape([](const std::string& s) { return s; });  // code, not HTML
  std::string out = tmpl.render(data);
  if (!tmpl.is_valid()) throw std::runtime_error(templatePath + ": " + tmpl.error_message());
  return TidyBlankLines(out);
}

std::string IndentTail(const std::string& text, const std::string& pad) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '\n' && i + 1 < text.size() && text[i + 1] != '\n') out += pad;
  }
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

const char* Axis(unsigned a) { return a == 0 ? "X" : a == 1 ? "Y" : "Z"; }

const char* GlAxis(unsigned a) { return a == 0 ? "x" : a == 1 ? "y" : "z"; }

std::vector<const Kernel*> VulkanKernels(const ClassModel& model) {
  std::vector<const Kernel*> all;
  for (auto& k : model.kernels) all.push_back(&k);
  for (auto& k : model.megakernels) all.push_back(&k);
  return all;
}

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
  if (k.dims == 1) return "crossrt::Dispatch1D(crt_cmd, crt_countX, " + std::to_string(s.x) + ")";
  if (k.dims == 2) return "crossrt::Dispatch2D(crt_cmd, crt_countX, crt_countY, " + std::to_string(s.x) + ", " + std::to_string(s.y) + ")";
  return "crossrt::Dispatch3D(crt_cmd, crt_countX, crt_countY, crt_countZ, " + std::to_string(s.x) + ", " + std::to_string(s.y) + ", " + std::to_string(s.z) + ")";
}

std::string LaunchSize(const Kernel& k) {
  if (k.dims == 1) return "std::min<uint32_t>(crt_countX, 65536u), (crt_countX + 65535u) / 65536u, 1";
  if (k.dims == 2) return "crt_countX, crt_countY, 1";
  return "crt_countX, crt_countY, crt_countZ";
}

std::string ReductionCppType(const ClassModel& model, const Reduction& r) {
  if (!r.cppType.empty()) return r.cppType;
  if (r.glslType == "double") return "double";  // ISPC's (the GPU has none)
  auto* m = FindMember(model, r.member);
  return m ? m->cppType : "float";
}

std::string ReductionElements(const Reduction& r) {
  const std::string dims = SplitArray(r.glslType).second;
  return dims.empty() ? "" : dims.substr(1, dims.size() - 2);
}

namespace {

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
    d.set("isPlain", m != nullptr && !m->padded3);
    d.set("isPadded", m != nullptr && m->padded3);  // 3-vectors held as 4-vectors: copied element by element
    d.set("computed", !f.assignExpr.empty());
    d.set("assignExpr", f.assignExpr);
    d.set("written", m != nullptr && m->writtenByKernels);
    list.push_back(d);
  }
  return list;
}

}  // namespace

Data CpuKernelData(const Kernel& k) {
  Data x;
    x.set("name", k.name);
    x.set("sourceFile", k.sourceFile);
    x.set("paramsDecl", k.cppParamsDecl);
    x.set("preamble", IndentTail(k.cpuPreamble, "  "));
    x.set("hasPreamble", !k.cpuPreamble.empty());
    x.set("postamble", IndentTail(k.cpuPostamble, "  "));
    x.set("hasPostamble", !k.cpuPostamble.empty());
  return x;
}

std::string KernelWayParam(const Kernel& k) { return std::string("crossrt::LaneChoice::Run& crt_way") + (k.cppParamsDecl.empty() ? "" : ", "); }

Data Common(const ClassModel& model, const GenerateOptions& opt) {
  Data d;
  d.set("className", model.className);
  d.set("generatedName", model.generatedName);
  d.set("symbolPrefix", model.symbolPrefix);
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
    x.set("paramsWithDefaults", c.paramsWithDefaults);
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
  d.set("hasThreadStates", !model.megakernels.empty() || std::any_of(model.controls.begin(), model.controls.end(), [](const Control& c) {
    return !c.threadStates.empty();  // a thread loop that runs wavefront only has no megakernel
  }));
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
  Data virtuals = List(), implIncludes = List(), hiddenMembers = List();
  std::set<std::string> headers, mirrored, hiddenTags;
  for (auto& v : model.virtuals) {
    Data x;
    x.set("member", v.member);
    x.set("host", v.hostExpr);
    x.set("display", v.display);
    x.set("interface", v.interfaceName);
    x.set("interfaceType", v.interfaceCpp);
    std::string names;
    Data impls = List();
    for (size_t t = 0; t < v.impls.size(); ++t) {
      const VirtualImpl& vi = v.impls[t];
      names += (t ? ", " : "") + vi.name;
      Data y;
      y.set("impl", vi.name);
      y.set("implType", vi.cppName);
      y.set("ispcData", IspcObjectStruct(vi.cppName));
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
        z.set("read", f.hostExpr);
        fields.push_back(z);
      }
      for (auto& h : vi.hidden) {
        if (!hiddenTags.insert(h.tag).second) continue;  // a base's member, read for another class already
        Data z;
        z.set("tag", h.tag);
        z.set("owner", h.owner);
        z.set("name", h.name);
        z.set("fieldType", h.fieldType);
        hiddenMembers.push_back(z);
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
    x.set("firstClassConstant", std::to_string(v.firstClassConstant));
    // Its elements are leaves the ray tracing hardware finds: their boxes are committed with it.
    x.set("leaves", std::any_of(model.kernels.begin(), model.kernels.end(), [&](const Kernel& k) {
            return RunsLeafShaders(k) && std::any_of(k.leaves.begin(), k.leaves.end(), [&](const LeafTraversal& lt) { return lt.member == v.member; });
          }));
    virtuals.push_back(x);
  }
  d.set("virtuals", virtuals);
  d.set("hasVirtuals", !model.virtuals.empty());
  std::string displays;
  for (auto& v : model.virtuals) displays += (displays.empty() ? "" : ", ") + v.display;
  d.set("virtualDisplays", displays);
  const unsigned classConstants = ClassConstantCount(model);
  d.set("classConstantCount", std::to_string(classConstants));
  Data specialized = List();
  const std::vector<const Member*> specializedMembers = SpecializedMembers(model);
  for (size_t i = 0; i < specializedMembers.size(); ++i) {
    Data x;
    x.set("name", specializedMembers[i]->name);
    x.set("host", specializedMembers[i]->hostExpr);
    x.set("constant", std::to_string(classConstants + i));  // its index in crt_pipelineConstants
    x.set("origin", specializedMembers[i]->composedFrom.empty() ? model.className + "::" + specializedMembers[i]->name
                                                                : specializedMembers[i]->composedFrom);
    specialized.push_back(x);
  }
  d.set("specializedMembers", specialized);
  d.set("hasSpecializedMembers", !specializedMembers.empty());
  d.set("hasSpecialization", classConstants > 0 || !specializedMembers.empty());
  d.set("constantCount", std::to_string(classConstants + specializedMembers.size()));
  d.set("classConstantBase", std::to_string(kClassConstantIdBase));
  d.set("virtualIncludes", implIncludes);
  d.set("hiddenMembers", hiddenMembers);
  d.set("hasHiddenMembers", !hiddenMembers.is_empty_list());
  return d;
}

unsigned ClassConstantCount(const ClassModel& model) {
  unsigned count = 0;
  for (auto& v : model.virtuals) count += unsigned(v.impls.size());
  return count;
}

std::vector<const Member*> SpecializedMembers(const ClassModel& model) {
  std::vector<const Member*> out;
  for (auto& m : model.members)
    if (m.specialized && m.usedByKernels) out.push_back(&m);
  return out;
}

}  // namespace crossrt::engine
