// Thread loops on the ISPC backend: `for (y) for (x) { locals; kernel_A(x, y, &local); ... }` in a
// control function of the ISPC class runs in SIMD lanes, one thread a lane. The loop's body, printed
// by ThreadBodyGlsl in the ISPC dialect, becomes a function of one thread that calls the kernels'
// ISPC thread functions (Kernels.cpp: IspcRtvHead); an export function runs it over a chunk of the
// threads (a 2D loop in tiles of rows and columns, as foreach_tiled spreads them); and the control
// function hands the chunks to all cores, in place of the loop, or runs the loop as the _CPU class
// does where that has been faster here (crossrt::LaneChoice). A loop nest around one kernel call
// (for (y) for (x) kernel_X(x, y, ...)) gets the same: its export function calls the kernel's
// thread function directly.

#include "analyse/AnalysisContext.h"
#include "generate/CodeGen.h"
#include "control/ControlFunctions.h"
#include "control/ControlRewriter.h"
#include "print/GlslTypes.h"
#include "print/ispc/IspcTypes.h"
#include "analyse/LoopShape.h"
#include "analyse/Naming.h"

#include <algorithm>

#include <clang/Lex/Lexer.h>

using namespace clang;

namespace crossrt::engine {

namespace {

// The control function's text in place of a loop nest: export function `symbol` over chunks of its
// threads on all cores (counts[a]: the threads along axis a, x first), then the members it set.
std::string ChunksOnAllCores(const ClassModel& model, const std::string& what, const std::string& symbol, size_t dims, const std::string counts[2],
                             const std::string& cppArgs) {
  const std::string outer = dims == 2 ? "crt_countY" : "crt_countX", chunk = std::to_string(dims == 2 ? kIspcTileRows : kIspcChunk1D);
  std::string text = "{  // " + what + ", in SIMD lanes: " + symbol + " in " + model.generatedName + "_kernels.ispc, in chunks of " +
                     (dims == 2 ? chunk + " rows" : chunk + " threads") + " on all cores\n"
                     "const ispc::" + model.symbolPrefix + "_Data crt_self = IspcData();\n"
                     "const int crt_countX = std::max(0, int(" + counts[0] + "));\n";
  if (dims == 2) text += "const int crt_countY = std::max(0, int(" + counts[1] + "));\n";
  text += "static const auto crt_run = crossrt::IspcPick(ispc::" + symbol + ", {" + IspcTargetFunctions(symbol) + "});\n"
          "static crossrt::ParallelChoice crt_choice;  // all cores, or this thread while that has been faster\n"
          "const auto crt_loop = crt_choice.Begin(" + outer + ", crt_way);\n"
          "crossrt::ParallelFor<int>(crt_loop.parallel, 0, (" + outer + " + " + chunk + " - 1) / " + chunk + ", 1, [&](int crt_first, int crt_last) {\n"
          "  for (int crt_chunk = crt_first; crt_chunk < crt_last; ++crt_chunk)\n"
          "    crt_run(const_cast<ispc::" + model.symbolPrefix + "_Data*>(&crt_self), crt_chunk * " + chunk + ", std::min(" + outer + ", (crt_chunk + 1) * " + chunk + ")" +
          (dims == 2 ? ", 0, crt_countX" : "") + cppArgs + ");\n"
          "});\n"
          "crt_choice.End(crt_loop);\n"
          "IspcWrittenBack(crt_self);  // members the kernels set\n}\n";
  return text;
}

// The threads of a loop nest of `dims` axes whose counts are counts[] (x first), as C++.
std::string Threads(const std::string counts[2], size_t dims) {
  return dims == 2 ? "(long long)std::max(0, int(" + counts[0] + ")) * std::max(0, int(" + counts[1] + "))" : "std::max(0, int(" + counts[0] + "))";
}

// The export function's loop over a chunk: x (and y) run across the lanes.
std::string ChunkLoop(size_t dims, const std::string& x, const std::string& y) {
  return dims == 2 ? "foreach_tiled (" + y + " = crt_begin ... crt_end, " + x + " = crt_startX ... crt_startX + crt_countX)"
                   : "foreach (" + x + " = crt_begin ... crt_end)";
}

// The export function's head, before the parameters of its own.
std::string ExportHead(const ClassModel& model, const std::string& symbol, size_t dims) {
  return "export void " + symbol + "(uniform " + model.symbolPrefix + "_Data *uniform self, uniform int crt_begin, uniform int crt_end" +
         (dims == 2 ? ", uniform int crt_startX, uniform int crt_countX" : "");
}

// The rows or threads an export function runs, for its comment.
std::string ChunkWhat(size_t dims) {
  return dims == 2 ? "rows [crt_begin, crt_end) of its threads, columns [crt_startX, crt_startX + crt_countX), in tiles"
                   : "threads [crt_begin, crt_end)";
}

}  // namespace

bool ControlRewriter::IspcThreadLoop(ThreadLoop& tl, const std::string& body, const ForStmt* outerLoop) {
  const size_t dims = tl.loops.size();
  if (dims > 2) return false;  // 3D loops stay C++, on all cores
  const std::string data = m_c.cls->getNameAsString() + "_Data", symbol = m_c.model.symbolPrefix + "_" + tl.mega.name;

  // One thread: its ids (x first, per lane), the control function's values (the gang's), the buffers.
  std::string head = "static void " + tl.mega.name + "(uniform " + data + " *uniform self";
  std::string exportHead = ExportHead(m_c.model, symbol, dims);
  std::string call = tl.mega.name + "(self", cppArgs;
  for (const KernelParam& p : tl.mega.params)
    if (p.isThreadId) {
      head += ", " + IspcTypeName(p.glslType) + " " + p.glslName;
      call += ", (" + IspcTypeName(p.glslType) + ")" + p.glslName;
    }
  std::string values;
  for (size_t i = 0; i < tl.mega.params.size(); ++i) {
    const KernelParam& p = tl.mega.params[i];
    if (p.isThreadId) continue;
    const auto [base, arrayDims] = SplitArray(IspcTypeName(p.glslType));
    std::string param;
    if (p.isPointer) {
      param = std::string(p.isConstPointee ? "const " : "") + "uniform " + base + " *uniform " + p.glslName;
      cppArgs += ", crossrt::IspcPointer<" + std::string(p.isConstPointee ? "const " : "") + IspcCppType(p.glslType) + "*>(" + tl.cppBufferArgs[i] + ")";
    } else if (IsIspcScalar(p.glslType) && arrayDims.empty()) {
      param = "uniform " + base + " " + p.glslName;
      cppArgs += ", " + p.name;
    } else if (arrayDims.empty()) {  // structs by reference: C++ passes them so
      param = "const uniform " + base + " &" + p.glslName;
      cppArgs += ", crossrt::IspcReference<" + IspcCppType(p.glslType) + ">(" + p.name + ")";
    } else {
      return false;  // an array the control function reads: the loop stays C++
    }
    head += ", " + param;
    exportHead += ", " + param;
    call += ", " + p.glslName;
  }
  tl.mega.glslBody = "// from " + m_c.cls->getNameAsString() + "::" + m_ctrl.name + " (" + m_ctrl.sourceFile +
                     "): the body of its thread loop for one thread (a SIMD lane), each kernel call a function call\n" + head + ")\n{\n" + body + "}\n";

  // A chunk of threads in SIMD lanes.
  std::vector<std::string> ids;  // x first
  for (const KernelParam& p : tl.mega.params)
    if (p.isThreadId) ids.push_back(p.glslName);
  const std::string x = ids.at(0), y = dims == 2 ? ids.at(1) : "";
  tl.mega.ispcExport = "// The thread loop of " + m_c.cls->getNameAsString() + "::" + m_ctrl.name + ": " + ChunkWhat(dims) + ", one thread a lane.\n" +
                       exportHead + ")\n{\n  " + ChunkLoop(dims, x, y) + "\n    " + call + ");\n}\n";

  // The control function: the chunks on all cores, in place of the loop.
  std::string counts[2];
  for (auto& h : tl.loops)
    if (auto axis = tl.axisOf.find(h.var); axis != tl.axisOf.end() && axis->second < dims) counts[axis->second] = CountExpr(m_c, h);
  LanesOrScalarLoop(outerLoop, tl.loops.front(), tl.loops.size(), ChunksOnAllCores(m_c.model, "the thread loop", symbol, dims, counts, cppArgs),
                    Threads(counts, dims));
  return true;
}

bool ControlRewriter::IspcRtvNest(const ForStmt* outer, const CXXMemberCallExpr* call, const std::map<unsigned, const LoopHeader*>& axes,
                                  const LoopHeader& outermost, size_t nestDepth) {
  const size_t dims = axes.size();
  auto* md = call->getMethodDecl();
  auto k = std::find_if(m_c.model.kernels.begin(), m_c.model.kernels.end(), [&](const Kernel& x) { return x.name == md->getNameAsString(); });
  if (dims > 2 || k == m_c.model.kernels.end() || k->returnsBool || k->params.size() != call->getNumArgs()) return false;
  const unsigned index = ++m_ispcNests;
  Kernel nest;
  nest.name = m_ctrl.name + "_" + k->name + (index > 1 ? std::to_string(index) : "");
  nest.megakernelCalls = {k->name};  // its code comes along (ClassLayout.cpp)
  const std::string symbol = m_c.model.symbolPrefix + "_" + nest.name;
  // The kernel's thread function takes its thread ids and by-value arguments per lane, then its
  // buffers and images (IspcRtvHead); the export function takes the latter two from the host.
  std::string exportHead = ExportHead(m_c.model, symbol, dims), threadArgs, bufferArgs, cppArgs;
  for (unsigned i = 0; i < k->params.size(); ++i) {
    const KernelParam& p = k->params[i];
    const Expr* arg = call->getArg(i);
    if (isa<CXXDefaultArgExpr>(arg) || p.threadState) return false;
    const auto [base, arrayDims] = SplitArray(IspcTypeName(p.glslType));
    const std::string text = ResolvedText(arg), name = "crt_" + p.glslName;  // apart from the lanes' ids
    if (p.isThreadId) {
      threadArgs += ", (" + base + ")crt_" + std::string(ThreadAxis(md->getParamDecl(i)->getName()) == 0 ? "x" : "y");
    } else if (p.isImage) {
      exportHead += ", const uniform crt_Image_" + base + " &" + name;
      bufferArgs += ", " + name;
      cppArgs += ", crossrt::IspcImage<ispc::crt_Image_" + base + ">(" + text + ")";
    } else if (p.isPointer) {
      exportHead += std::string(", ") + (p.isConstPointee ? "const " : "") + "uniform " + base + " *uniform " + name;
      bufferArgs += ", " + name;
      cppArgs += ", crossrt::IspcPointer<" + std::string(p.isConstPointee ? "const " : "") + IspcCppType(p.glslType) + "*>(" + text + ")";
    } else if (!arrayDims.empty()) {
      return false;  // an array by value: the nest stays C++
    } else if (IsIspcScalar(p.glslType)) {
      exportHead += ", uniform " + base + " " + name;
      threadArgs += ", " + name;
      cppArgs += ", " + IspcCppType(p.glslType) + "(" + text + ")";
    } else {
      exportHead += ", const uniform " + base + " &" + name;
      threadArgs += ", " + name;
      cppArgs += ", crossrt::IspcReference<" + IspcCppType(p.glslType) + ">(" + text + ")";
    }
  }
  nest.ispcExport = "// The loop nest of " + m_c.cls->getNameAsString() + "::" + m_ctrl.name + " around " + k->name + ": " + ChunkWhat(dims) +
                    ", one thread a lane.\n" + exportHead + ")\n{\n  " + ChunkLoop(dims, "crt_x", "crt_y") + "\n    " + k->name + "(self" + threadArgs +
                    bufferArgs + ");\n}\n";
  m_c.model.megakernels.push_back(nest);
  std::string counts[2];
  for (auto& [axis, h] : axes)
    if (axis < dims) counts[axis] = CountExpr(m_c, *h);
  LanesOrScalarLoop(outer, outermost, nestDepth, ChunksOnAllCores(m_c.model, "the loop nest", symbol, dims, counts, cppArgs), Threads(counts, dims));
  return true;
}

void ControlRewriter::LanesOrScalarLoop(const ForStmt* loop, const LoopHeader& outermost, size_t nest, const std::string& lanes, const std::string& threads) {
  SourceLocation end = Lexer::findLocationAfterToken(loop->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
  CharSourceRange range = end.isValid() ? CharSourceRange::getCharRange(loop->getBeginLoc(), end) : CharSourceRange::getTokenRange(loop->getSourceRange());
  const auto [before, after] = ParallelChoiceAround(loop, outermost, nest, "crt_way");
  std::string scalar = before + m_cpu.getRewrittenText(range) + after + "\n";
  if (!m_c.model.virtuals.empty())  // as the lanes' class data does: an element without an object throws
    scalar = "{\n(void)IspcData();  // checks the vectors of objects as the lanes' way does\n" + scalar + "}\n";
  m_cpu.ReplaceText(range, "{  // in SIMD lanes, or as the _CPU class runs it, whichever has been faster here (crossrt::LaneChoice)\n"
                           "static crossrt::LaneChoice crt_lanes(\"" + m_c.cls->getQualifiedNameAsString() + "::" + m_md->getNameAsString() +
                           ", a loop of it\");\n"
                           "crossrt::LaneChoice::Run crt_way = crt_lanes.Begin();\n"
                           "crt_way.iterations = " + threads + ";\n"
                           "if (crt_way.lanes)\n" + lanes + "else\n" + scalar + "crt_lanes.End(crt_way);\n}\n");
}

}  // namespace crossrt::engine
