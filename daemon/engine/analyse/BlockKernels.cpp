// kernel_slicer's block-expansion kernels: see BlockKernels.h.
#include "analyse/BlockKernels.h"

#include "analyse/AstQueries.h"
#include "analyse/CpuCopies.h"
#include "analyse/LoopShape.h"
#include "generate/Canonical.h"

#include <clang/Rewrite/Core/Rewriter.h>

#include <regex>

using namespace clang;

namespace crossrt::engine {

bool IsBlockKernelName(llvm::StringRef name) { return name.starts_with("kernelBE1D_") || name.starts_with("kernelBE2D_") || name.starts_with("kernelBE3D_"); }

namespace {

// The CPU class's copy of the kernel: the loop over blocks on all cores (crossrt::ParallelFor, or an
// OpenMP pragma where its header is not `for (T i = a; i < b; ++i)`), the [[parallel]]
// markers of the block's loops dropped (each block's thread runs them in order).
void AddBlockKernel(Context& c, const FunctionDecl* decl, const FunctionDecl* def, const TemplateParameterList* params) {
  const ForStmt* blocks = nullptr;
  if (auto* body = dyn_cast<CompoundStmt>(def->getBody()))
    for (auto* s : body->body())
      if ((blocks = dyn_cast<ForStmt>(s))) break;
  if (!blocks) {
    c.rep.Error(decl->getLocation(), "block-expansion kernel '" + decl->getNameAsString() + "' has no loop over its blocks",
                "a kernelBE1D_ kernel holds for (blockId = 0; blockId < blockNum; blockId++) { ... } whose iterations are the blocks");
    return;
  }
  BlockKernel k;
  k.name = decl->getNameAsString();
  k.sourceFile = BaseName(FileOf(c.ctx, def->getLocation()));
  if (auto* ft = def->getDescribedFunctionTemplate()) params = ft->getTemplateParameters();  // as the definition names them
  if (params) k.templateHead = c.Text(params->getSourceRange());
  for (unsigned i = 0; i < def->getNumParams(); ++i) k.paramsDecl += (i ? ", " : "") + ParamDecl(c.ctx, def->getParamDecl(i), i);
  Rewriter rw(c.ctx.getSourceManager(), c.ctx.getLangOpts());
  // The blocks on all cores, or on this thread while that has been faster (crossrt::ParallelChoice, as
  // every other parallel loop of the CPU class), taken one at a time by whichever thread is free.
  LoopHeader h;
  if (LoopShapeProblem(c.ctx, blocks, h).empty() && isa<CompoundStmt>(blocks->getBody())) {
    const std::string count = CountExpr(c, h);
    const ChunkedLoop chunked = ChunkLoop(rw, c.ctx, blocks, h, "crt_loop.parallel", "1");
    rw.InsertTextBefore(blocks->getBeginLoc(), "static crossrt::ParallelChoice crt_choice;\nconst auto crt_loop = crt_choice.Begin(" + count + ");\n" +
                                                   chunked.head + "  // the blocks\n");
    rw.InsertTextAfterToken(blocks->getEndLoc(), "\n" + chunked.tail + "\ncrt_choice.End(crt_loop);");
  } else {
    rw.InsertTextBefore(blocks->getBeginLoc(), "#pragma omp parallel for schedule(dynamic)  // the blocks, one per core at a time\n");
  }
  const std::string body = rw.getRewrittenText(def->getBody()->getSourceRange());
  k.body = CanonicalCode(std::regex_replace(body, std::regex(R"(\[\[\s*parallel\s*\]\])"), ""));
  c.model.blockKernels.push_back(k);
  CopySourceDeclarations(c, def->getBody(), "kernel '" + k.name + "'");  // static helpers and constants of the .cpp it calls
}

}  // namespace

void AnalyzeBlockKernels(Context& c) {
  const bool cpu = c.model.forCpu && !c.model.forIspc;
  auto visit = [&](const FunctionDecl* decl, const TemplateParameterList* params) {
    for (auto& k : c.model.blockKernels)
      if (k.name == decl->getNameAsString()) return;  // seen in another source file
    const FunctionDecl* def = nullptr;
    if (!cpu) {
      c.rep.Error(decl->getLocation(), "'" + decl->getNameAsString() + "' is one of kernel_slicer's block-expansion kernels (kernelBE1D_), which " +
                                           (c.model.forIspc ? "the ISPC" : "the GPU") + " backend does not translate",
                  "the CPU backend runs it, a block per core; here write it as a kernel1D_ loop with one iteration per thread, and keep work "
                  "that a block shares in a separate kernel or a reduction");
      return;
    }
    if (decl->hasBody(def) && def) AddBlockKernel(c, decl, def, params);
  };
  for (auto* d : c.cls->decls()) {
    if (auto* ft = dyn_cast<FunctionTemplateDecl>(d); ft && IsBlockKernelName(ft->getName()))
      visit(ft->getTemplatedDecl(), ft->getTemplateParameters());
    else if (auto* md = dyn_cast<CXXMethodDecl>(d); md && IsBlockKernelName(md->getName()))
      visit(md, nullptr);
  }
}

}  // namespace crossrt::engine
