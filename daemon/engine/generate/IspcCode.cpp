// The ISPC backend's code: <Class>_ISPC_kernels.ispc (the kernels' thread functions as the printer
// wrote them in its ISPC dialect, and an export function per kernel that runs one chunk of the loop
// nest in SIMD lanes) and the data the ISPC class's host code needs to call them (IspcHostData:
// the class data it fills, the chunks it hands to the cores and how it folds their reductions).
#include "generate/CodeGen.h"
#include "generate/CodeGenSupport.h"
#include "generate/GeneratedNames.h"
#include "print/GlslTypes.h"
#include "print/ispc/IspcTypes.h"

#include <algorithm>
#include <set>

namespace crossrt::engine {

namespace {

// The ISA suffixes of the objects ISPC writes for cmake/CrossRT.cmake's targets, in that order
// (crossrt::IspcPick in runtime/include/crossrt/IspcSupport.h takes them so).
const char* const kIspcTargetSuffixes[] = {"sse4", "avx2", "avx512skx"};

bool IsScalar(const std::string& glslType) { return IsIspcScalar(glslType); }

// The identity of a reduction, in ISPC: a lane that ran no iteration changes nothing.
std::string IspcIdentity(ReduceOp op, const std::string& glslType) {
  const std::string t = IspcTypeName(glslType);
  const bool floating = t.rfind("float", 0) == 0;
  if (t == "double")
    return op == ReduceOp::Min ? "doublebits(0x7FF0000000000000ull)" : op == ReduceOp::Max ? "doublebits(0xFFF0000000000000ull)" : "0.0d";
  std::string scalar = "0";
  if (op == ReduceOp::Min) scalar = floating ? "floatbits(0x7F800000u)" : t.rfind("uint", 0) == 0 ? "0xFFFFFFFFu" : "2147483647";
  if (op == ReduceOp::Max) scalar = floating ? "floatbits(0xFF800000u)" : t.rfind("uint", 0) == 0 ? "0u" : "(-2147483647 - 1)";
  if (op != ReduceOp::Min && op != ReduceOp::Max && floating) scalar = "0.0f";
  return IsScalar(glslType) ? scalar : "make_" + t + "(" + scalar + ")";
}

// The lanes' accumulators reduced to one uniform value, component by component, into *partial (or,
// with `element`, into the lvalue `partial`; the lines joined by `newline`).
std::string IspcLaneReduce(ReduceOp op, const std::string& glslType, const std::string& v, const std::string& partial,
                           const std::string& newline = "\n  ", bool element = false) {
  const std::string f = op == ReduceOp::Min ? "reduce_min" : op == ReduceOp::Max ? "reduce_max" : "reduce_add";
  if (IsScalar(glslType)) return (element ? "" : "*") + partial + " = " + f + "(" + v + ");";
  const int n = IspcTypeName(glslType).back() - '0';
  std::string out;
  for (int i = 0; i < n; ++i) out += std::string(i ? newline : "") + partial + (element ? "." : "->") + "xyzw"[i] + " = " + f + "(" + v + "." + "xyzw"[i] + ");";
  return out;
}

// The order GLSL's thread ids come in: x (the innermost loop) first.
const char* Axis(unsigned d, unsigned dims) {
  const unsigned fromInnermost = d < dims ? dims - 1 - d : 0;
  return fromInnermost == 0 ? "X" : fromInnermost == 1 ? "Y" : "Z";
}

}  // namespace

// What C++ passes for an ISPC parameter of this GLSL type: the type ispc::'s header declares.
std::string IspcCppType(const std::string& glslType) {
  if (glslType == "int") return "int32_t";
  if (glslType == "uint") return "uint32_t";
  if (IsScalar(glslType)) return glslType;
  return "ispc::" + IspcTypeName(glslType);
}

bool IsIspcScalar(const std::string& glslType) {
  return glslType == "float" || glslType == "int" || glslType == "uint" || glslType == "bool" || glslType == "double";
}

std::string IspcTargetFunctions(const std::string& symbol) {
  std::string targets;
  for (const char* t : kIspcTargetSuffixes) targets += std::string(targets.empty() ? "" : ", ") + symbol + "_" + t;
  return targets;
}

std::string GenerateIspcKernels(const ClassModel& model, const GenerateOptions& opt) {
  Data d = Common(model, opt);
  // Declarations once each, in the order the printers met them: the class's structs, then the
  // kernels' own, their constants and helper functions (callees before callers).
  std::string structs = model.glslClassStructs;
  std::set<std::string> seen(model.glslClassStructNames.begin(), model.glslClassStructNames.end());
  std::vector<std::string> functions;
  std::string constants;
  auto takeDeclarations = [&](const Kernel& k) {  // what k's code needs, each once
    for (auto& s : k.structList)
      if (seen.insert(s.name).second) structs += s.text + "\n";
    for (auto& c : k.constantList)
      if (seen.insert(c.name).second) constants += c.text;
    for (auto& f : k.functionList)
      if (std::find(functions.begin(), functions.end(), f) == functions.end()) functions.push_back(f);
  };
  Data kernels = List();
  for (const Kernel& k : model.kernels) {
    if (k.rtv) continue;
    takeDeclarations(k);
    functions.push_back(k.glslBody);

    Data x;
    x.set("name", k.name);
    x.set("sourceFile", k.sourceFile);
    // The outermost loop is cut into chunks [crt_begin, crt_end); the inner ones run whole.
    std::string params, innerParams, args, loopsOpen, ids;
    const unsigned dims = unsigned(k.loops.size());
    for (unsigned a = 1; a < dims; ++a) innerParams += std::string(", uniform int crt_start") + Axis(a, dims) + ", uniform int crt_count" + Axis(a, dims);
    std::string indent = "  ";
    if (k.ispcTiled) {  // rows and columns across the lanes (Kernel::ispcTiled)
      loopsOpen = indent + "foreach_tiled (" + k.loops[0].var + " = crt_begin ... crt_end, " + k.loops[1].var + " = crt_startX ... crt_startX + crt_countX)\n";
      indent += "  ";
    }
    for (unsigned a = 0; a < dims && !k.ispcTiled; ++a) {
      const std::string var = k.loops[a].var, axis = Axis(a, dims);
      if (a + 1 < dims) {
        loopsOpen += indent + "for (uniform int " + var + " = " + (a == 0 ? "crt_begin" : "crt_start" + axis) + "; " + var + " < " +
                     (a == 0 ? "crt_end" : "crt_start" + axis + " + crt_count" + axis) + "; ++" + var + ")\n";
      } else {
        loopsOpen += indent + "foreach (" + var + " = " + (a == 0 ? "crt_begin ... crt_end" : "crt_start" + axis + " ... crt_start" + axis + " + crt_count" + axis) + ")\n";
      }
      indent += "  ";
    }
    for (unsigned a = dims; a-- > 0;) ids += ", " + k.loops[a].var;  // x first, as the thread function takes them
    for (auto& p : k.params) {
      const auto [base, dims2] = SplitArray(IspcTypeName(p.glslType));
      if (p.isPointer) params += std::string(", ") + (p.isConstPointee ? "const " : "") + "uniform " + base + " *uniform " + p.glslName;
      else if (p.isImage) params += ", const uniform crt_Image_" + base + " &" + p.glslName;
      else if (IsScalar(p.glslType)) params += ", uniform " + base + " " + p.glslName + dims2;
      else params += ", const uniform " + base + " &" + p.glslName;  // structs by reference: C++ passes them so
      args += ", " + p.glslName;
    }
    Data reds = List();
    for (auto& r : k.reductions) {
      const auto [base, dims] = SplitArray(IspcTypeName(r.glslType));
      const std::string local = generated::ReductionLocal(r.member), partials = generated::ReductionPartials(r.member);
      const std::string elements = ReductionElements(r), baseGlsl = SplitArray(r.glslType).first;
      params += ", uniform " + base + " *uniform " + partials;
      args += ", " + local;
      Data y;
      if (elements.empty()) {
        y.set("declare", base + " " + local + " = " + IspcIdentity(r.op, r.glslType) + ";");
        y.set("reduced", IspcLaneReduce(r.op, r.glslType, local, partials));
      } else {  // the elements of an array (coefs[k] += x, bins[b] += x): an array a lane, reduced element by element
        const std::string each = "for (uniform int crt_e = 0; crt_e < " + elements + "; ++crt_e)";
        y.set("declare", base + " " + local + "[" + elements + "];  // this lane's part of each element of " + r.member + "\n  " + each +
                             "\n    " + local + "[crt_e] = " + IspcIdentity(r.op, baseGlsl) + ";");
        y.set("reduced", each + (IsScalar(baseGlsl) ? "\n    " : "\n  {\n    ") +
                             IspcLaneReduce(r.op, baseGlsl, local + "[crt_e]", partials + "[crt_e]", "\n    ", true) + (IsScalar(baseGlsl) ? "" : "\n  }"));
      }
      reds.push_back(y);
    }
    x.set("params", innerParams + params);
    x.set("loops", loopsOpen);
    x.set("call", indent + k.name + "(self" + ids + args + ");");
    x.set("reductions", reds);
    kernels.push_back(x);
  }
  // Thread loops run in SIMD lanes: their kernels' code, the body of one thread, and the export
  // function of a chunk (IspcThreadLoops.cpp).
  std::string exports;
  for (const Kernel& mk : model.megakernels) {
    if (mk.ispcExport.empty()) continue;
    takeDeclarations(mk);
    if (!mk.glslBody.empty()) functions.push_back(mk.glslBody);  // (a loop nest around one kernel calls it directly)
    exports += mk.ispcExport + "\n";
  }
  std::string code;
  for (auto& f : functions) code += f + "\n";
  code += exports;
  d.set("structs", structs);
  d.set("constants", constants);
  d.set("functions", code);
  d.set("kernels", kernels);
  const bool threadLoops = std::any_of(model.megakernels.begin(), model.megakernels.end(), [](const Kernel& mk) { return !mk.ispcExport.empty(); });
  d.set("ispcHasKernels", !kernels.is_empty_list() || threadLoops);  // else no <Class>_Data: nothing declares the types of its members
  Data members = List(), vectors = List();
  for (auto& m : model.members) {
    if (!m.usedByKernels) continue;
    Data x;
    x.set("name", m.name);
    const auto [base, dims] = SplitArray(IspcTypeName(m.glslType));
    x.set("declaration", (m.kind == MemberKind::Vector ? "uniform " + base + " *" + m.name : base + " " + m.name + dims) + ";");
    if (m.kind == MemberKind::Image) x.set("declaration", "crt_Image_" + base + " " + m.name + ";");  // LiteMath.isph's
    if (m.kind == MemberKind::Sampler) x.set("declaration", "crt_Sampler " + m.name + ";");
    if (m.kind == MemberKind::TextureArray) x.set("declaration", "uniform crt_Texture_" + base + " *" + m.name + ";");
    if (m.kind == MemberKind::Plain || m.kind == MemberKind::Image || m.kind == MemberKind::Sampler) members.push_back(x);
    if (m.kind == MemberKind::Vector || m.kind == MemberKind::TextureArray) vectors.push_back(x);
  }
  d.set("members", members);
  d.set("vectors", vectors);
  return Render(opt.templateDir + "/ispc/kernels.ispc.mustache", d);
}

void IspcHostData(const ClassModel& model, Data& d) {
  // A plain member of the class's own that kernels set: it goes back from the ISPC class data.
  auto writtenBack = [](const Member& m) { return m.kind == MemberKind::Plain && m.usedByKernels && m.writtenByKernels && m.composedFrom.empty(); };
  Data members = List(), vectors = List(), textures = List();
  for (auto& m : model.members) {
    if (!m.usedByKernels) continue;
    Data x;
    x.set("name", m.name);
    x.set("expr", m.hostExpr.empty() ? m.name : m.hostExpr);  // a composed member: through its holder
    if (!m.composedFrom.empty()) x.set("composedFrom", m.composedFrom);  // its comment
    if (m.kind == MemberKind::Image) x.set("image", "ispc::crt_Image_" + IspcTypeName(m.glslType));
    if (m.kind == MemberKind::TextureArray) {
      x.set("texture", "ispc::crt_Texture_" + IspcTypeName(m.glslType));
      x.set("combined", m.combinedSamplers);  // ICombinedImageSampler pointers: their texels as float4 textures
      x.set("textures", m.combinedSamplers ? "crt_" + m.name + "Texels" : (m.hostExpr.empty() ? m.name : m.hostExpr));
    }
    if (m.kind == MemberKind::Plain || m.kind == MemberKind::Image || m.kind == MemberKind::Sampler) members.push_back(x);
    if (m.kind == MemberKind::Vector) vectors.push_back(x);
    if (m.kind == MemberKind::TextureArray) textures.push_back(x);
  }
  d.set("ispcMembers", members);
  d.set("ispcTextures", textures);
  d.set("ispcVectors", vectors);
  Data kernels = List();
  for (const Kernel& k : model.kernels) {
    if (k.rtv) continue;
    Data x = CpuKernelData(k);
    const unsigned dims = unsigned(k.loops.size());
    Data loops = List();
    std::string innerArgs;
    for (unsigned a = 0; a < dims; ++a) {
      Data l;
      l.set("axis", Axis(a, dims));
      l.set("start", k.loops[a].startCpp);
      l.set("count", k.loops[a].countCpp);
      loops.push_back(l);
      if (a > 0) innerArgs += std::string(", crt_start") + Axis(a, dims) + ", crt_count" + Axis(a, dims);
    }
    x.set("loops", loops);
    x.set("outer", Axis(0, dims));
    x.set("chunk", std::to_string(dims == 1 ? kIspcChunk1D : k.ispcTiled ? kIspcTileRows : 1));
    x.set("chunkWhat", dims == 1      ? std::to_string(kIspcChunk1D) + " iterations"
                       : k.ispcTiled ? std::to_string(kIspcTileRows) + " rows, in tiles of rows and columns (foreach_tiled)"
                       : dims == 2    ? "one row"
                                      : "one slice");
    x.set("innerArgs", innerArgs);
    std::string args;
    for (auto& p : k.params) {
      if (p.isPointer) args += ", crossrt::IspcPointer<" + std::string(p.isConstPointee ? "const " : "") + IspcCppType(p.glslType) + "*>(" + p.name + ")";
      else if (p.isImage) args += ", crossrt::IspcImage<ispc::crt_Image_" + IspcTypeName(p.glslType) + ">(" + p.name + ")";
      else if (IsScalar(p.glslType)) args += ", " + p.name;
      else args += ", crossrt::IspcReference<" + IspcCppType(p.glslType) + ">(" + p.name + ")";
    }
    Data reds = List();
    for (auto& r : k.reductions) {
      // An array's elements (coefs[k] += x, bins[b] += x): each chunk's partials are elements of their own.
      const std::string cppType = ReductionCppType(model, r), elements = ReductionElements(r), baseGlsl = SplitArray(r.glslType).first;
      const std::string partials = generated::ReductionPartials(r.member);
      args += ", crossrt::IspcPointer<" + IspcCppType(baseGlsl) + "*>(&" + partials + "[crt_chunk" + (elements.empty() ? "" : " * " + elements) + "])";
      Data y;
      y.set("member", r.member);
      y.set("cppType", cppType);
      y.set("partialCount", elements.empty() ? "crt_chunks" : "crt_chunks * " + elements);
      const std::string target = elements.empty() ? r.member : r.member + "[crt_at % " + elements + "]";
      const std::string partial = elements.empty() ? "partial" : partials + "[crt_at]";
      y.set("foldHead", elements.empty() ? "for (const auto& partial : " + partials + ")"
                                         : "for (size_t crt_at = 0; crt_at < " + partials + ".size(); ++crt_at)  // chunk crt_at / " + elements +
                                               ", element crt_at % " + elements);
      y.set("target", target);
      const char* ns = IsScalar(baseGlsl) ? "std::" : "LiteMath::";
      y.set("fold", r.op == ReduceOp::Min   ? std::string(ns) + "min(" + target + ", " + partial + ")"
                    : r.op == ReduceOp::Max ? std::string(ns) + "max(" + target + ", " + partial + ")"
                                            : target + " + " + partial);
      reds.push_back(y);
    }
    // Plain members the kernels write (atomics among them) go back from the ISPC class data after
    // the chunks; this kernel's reductions are folded from their partials instead.
    Data written = List();
    for (auto& m : model.members) {
      const bool reduced = std::any_of(k.reductions.begin(), k.reductions.end(), [&](const Reduction& r) { return !r.local && r.member == m.name; });
      if (!writtenBack(m) || reduced) continue;
      Data w;
      w.set("name", m.name);
      written.push_back(w);
    }
    x.set("args", args);
    x.set("reductions", reds);
    x.set("hasReductions", !reds.is_empty_list());
    x.set("writtenMembers", written);
    // The loop nest's own copies of the locals declared before it are computed in the ISPC kernel:
    // the host's may go unused (by the statements after the nest, or a reduction into them).
    std::string unused;
    for (auto& l : k.preambleLocals) unused += "(void)" + l + "; ";
    x.set("preambleLocals", unused.empty() ? "" : unused + " // the ISPC kernel computes its own");
    x.set("targetFunctions", IspcTargetFunctions(model.symbolPrefix + "_" + k.name));
    // The kernel runs one of two ways (crossrt::LaneChoice): this one, or HostCode's scalar loop.
    x.set("lanesMethod", generated::LanesMethod(k.name));
    x.set("scalarMethod", generated::ScalarMethod(k.name));
    x.set("wayParam", KernelWayParam(k));
    x.set("wayArgs", "crt_way" + std::string(k.cppArgs.empty() ? "" : ", ") + k.cppArgs);
    kernels.push_back(x);
  }
  // The thread loops that run in SIMD lanes: their export functions, per target.
  Data threadLoops = List();
  for (const Kernel& mk : model.megakernels) {
    if (mk.ispcExport.empty()) continue;
    Data x;
    x.set("symbol", model.symbolPrefix + "_" + mk.name);
    x.set("targetFunctions", IspcTargetFunctions(model.symbolPrefix + "_" + mk.name));
    threadLoops.push_back(x);
  }
  d.set("ispcThreadLoops", threadLoops);
  d.set("ispcHasThreadLoops", !threadLoops.is_empty_list());
  Data writtenMembers = List();
  for (auto& m : model.members)
    if (writtenBack(m)) {
      Data w;
      w.set("name", m.name);
      writtenMembers.push_back(w);
    }
  d.set("ispcWrittenMembers", writtenMembers);
  d.set("ispcHasKernels", !kernels.is_empty_list() || !threadLoops.is_empty_list());  // else ISPC declares no <Class>_Data
  // The vectors kernels append to: the ISPC kernels hand the values to the class.
  Data appends = List();
  for (auto& m : model.members)
    if (m.appendedByKernels && m.kind == MemberKind::Vector && m.composedFrom.empty()) {
      Data x;
      x.set("name", m.name);
      appends.push_back(x);
    }
  d.set("ispcAppends", appends);
  d.set("ispcKernels", kernels);
  d.set("ispcHasKernelWays", !kernels.is_empty_list());
}

}  // namespace crossrt::engine
