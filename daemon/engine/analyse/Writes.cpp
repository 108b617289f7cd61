// What a kernel writes: member reductions (+=, min, max on members), appends, atomics, member writes
// and constant stores (WriteScanner), and reductions of locals declared before the loop nest
// (LocalReductionScanner). Takes a kernel's body; gives the writes each later pass must translate.
#include "analyse/Writes.h"

#include "analyse/AnalysisContext.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

std::string Identity(ReduceOp op, const std::string& glslType) {
  std::string scalar = glslType.find("vec") == std::string::npos ? glslType
                       : glslType[0] == 'i' ? "int" : glslType[0] == 'u' ? "uint" : "float";
  std::string v;
  if (op == ReduceOp::Add || op == ReduceOp::Sub) v = scalar == "float" ? "0.0" : scalar == "uint" ? "0u" : "0";
  // +-infinity (CRT_INFINITY, defined by the shader templates), so that infinite inputs reduce
  // exactly as on the CPU
  else if (op == ReduceOp::Min) v = scalar == "float" ? "CRT_INFINITY" : scalar == "uint" ? "0xFFFFFFFFu" : "0x7FFFFFFF";
  else v = scalar == "float" ? "-CRT_INFINITY" : scalar == "uint" ? "0u" : "(-2147483647 - 1)";
  return glslType == scalar ? v : glslType + "(" + v + ")";
}

std::string StatementText(Context& c, const Stmt* s) {
  auto& sm = c.ctx.getSourceManager();
  SourceLocation end = Lexer::findLocationAfterToken(s->getEndLoc(), tok::semi, sm, c.ctx.getLangOpts(), false);
  if (end.isValid()) return Lexer::getSourceText(CharSourceRange::getCharRange(sm.getExpansionLoc(s->getBeginLoc()), end), sm, c.ctx.getLangOpts()).str();
  return c.Text(s->getSourceRange());
}

void LocalReductionReads(Context& c, const std::string& kernel, const LocalReductionScanner& scan, const Stmt* threadBody) {
  struct Reads : RecursiveASTVisitor<Reads> {
    Context& c; const std::string& kernel; const LocalReductionScanner& scan;
    Reads(Context& ctx, const std::string& k, const LocalReductionScanner& s) : c(ctx), kernel(k), scan(s) {}
    bool VisitDeclRefExpr(DeclRefExpr* e) {
      auto* vd = dyn_cast<VarDecl>(e->getDecl());
      if (vd && scan.reductions.count(vd) && !scan.uses.count(e))
        c.rep.Error(e->getLocation(), "the loop of kernel '" + kernel + "' reads '" + vd->getNameAsString() + "', which its iterations reduce",
                    "its total is known after the loop: read it in the statements after the loop nest");
      return true;
    }
  } reads(c, kernel, scan);
  reads.TraverseStmt(const_cast<Stmt*>(threadBody));
}

}  // namespace crossrt::engine
