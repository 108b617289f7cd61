// Thread loops on the ISPC backend: `for (y) for (x) { locals; kernel_A(x, y, &local); ... }` in a
// control function of the ISPC class runs in SIMD lanes, one thread a lane. The loop's body, printed
// by ThreadBodyGlsl in the ISPC dialect, becomes a function of one thread that calls the kernels'
// ISPC thread functions (Kernels.cpp: IspcRtvHead); an export function runs it over a chunk of the
// threads (a 2D loop in tiles of rows and columns, as foreach_tiled spreads them); and the control
// function hands the chunks to all cores, in place of the loop.

#include "AnalysisContext.h"
#include "CodeGen.h"
#include "ControlFunctions.h"
#include "ControlRewriter.h"
#include "GlslTypes.h"
#include "LoopShape.h"

#include <clang/Lex/Lexer.h>

using namespace clang;

namespace crossrt::engine {

namespace {

constexpr int kChunk1D = 4096;  // threads per chunk of a 1D loop
constexpr int kTileRows = 4;    // rows per chunk of a 2D loop: a foreach_tiled tile is up to 4 rows high

bool IsScalarGlsl(const std::string& t) { return t == "float" || t == "int" || t == "uint" || t == "bool" || t == "double"; }

}  // namespace

bool ControlRewriter::IspcThreadLoop(ThreadLoop& tl, const std::string& body, const ForStmt* outerLoop) {
  const size_t dims = tl.loops.size();
  if (dims > 2) return false;  // 3D loops stay C++, on all cores
  const std::string data = m_c.cls->getNameAsString() + "_Data", symbol = m_c.model.symbolPrefix + "_" + tl.mega.name;

  // One thread: its ids (x first, per lane), the control function's values (the gang's), the buffers.
  std::string head = "static void " + tl.mega.name + "(uniform " + data + " *uniform self";
  std::string exportHead = "export void " + symbol + "(uniform " + m_c.model.symbolPrefix + "_Data *uniform self, uniform int crt_begin, uniform int crt_end";
  if (dims == 2) exportHead += ", uniform int crt_startX, uniform int crt_countX";
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
    } else if (IsScalarGlsl(p.glslType) && arrayDims.empty()) {
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
  const std::string loop = dims == 2 ? "foreach_tiled (" + y + " = crt_begin ... crt_end, " + x + " = crt_startX ... crt_startX + crt_countX)"
                                     : "foreach (" + x + " = crt_begin ... crt_end)";
  tl.mega.ispcExport = "// The thread loop of " + m_c.cls->getNameAsString() + "::" + m_ctrl.name + ": " +
                       (dims == 2 ? "rows [crt_begin, crt_end) of its threads, columns [crt_startX, crt_startX + crt_countX), in tiles"
                                  : "threads [crt_begin, crt_end)") +
                       ", one thread a lane.\n" + exportHead + ")\n{\n  " + loop + "\n    " + call + ");\n}\n";

  // The control function: the chunks on all cores, in place of the loop.
  std::string counts[2];
  for (auto& h : tl.loops)
    if (auto axis = tl.axisOf.find(h.var); axis != tl.axisOf.end() && axis->second < dims) counts[axis->second] = CountExpr(m_c, h);
  const std::string outer = dims == 2 ? "crt_countY" : "crt_countX", chunk = std::to_string(dims == 2 ? kTileRows : kChunk1D);
  std::string text = "{  // the thread loop, in SIMD lanes: " + tl.mega.name + " in " + m_c.model.generatedName + "_kernels.ispc, in chunks of " +
                     (dims == 2 ? std::to_string(kTileRows) + " rows" : chunk + " threads") + " on all cores\n"
                     "const ispc::" + m_c.model.symbolPrefix + "_Data crt_self = IspcData();\n"
                     "const int crt_countX = std::max(0, int(" + counts[0] + "));\n";
  if (dims == 2) text += "const int crt_countY = std::max(0, int(" + counts[1] + "));\n";
  text += "static const auto crt_run = crossrt::IspcPick(ispc::" + symbol + ", {" + IspcTargetFunctions(symbol) + "});\n"
          "#pragma omp parallel for schedule(dynamic, 1)\n"
          "for (int crt_chunk = 0; crt_chunk < (" + outer + " + " + chunk + " - 1) / " + chunk + "; ++crt_chunk)\n"
          "  crt_run(const_cast<ispc::" + m_c.model.symbolPrefix + "_Data*>(&crt_self), crt_chunk * " + chunk + ", std::min(" + outer + ", (crt_chunk + 1) * " + chunk + ")" +
          (dims == 2 ? ", 0, crt_countX" : "") + cppArgs + ");\n"
          "IspcWrittenBack(crt_self);  // members the kernels set\n}\n";
  SourceLocation end = Lexer::findLocationAfterToken(outerLoop->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
  CharSourceRange range = end.isValid() ? CharSourceRange::getCharRange(outerLoop->getBeginLoc(), end) : CharSourceRange::getTokenRange(outerLoop->getSourceRange());
  m_cpu.ReplaceText(range, text);
  return true;
}

}  // namespace crossrt::engine
