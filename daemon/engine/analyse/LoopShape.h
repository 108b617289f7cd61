// The shape of a kernel's loop nest: one parser of `for (int i = begin; i < end; ++i)` headers
// (ParseLoop, quiet or reporting), their thread counts, and what may stand before and after the nest.
#pragma once
#include "analyse/AnalysisContext.h"

#include <clang/Rewrite/Core/Rewriter.h>

namespace crossrt::engine {

// The statements before a kernelND_'s loop nest that do nothing but set locals declared before it
// (`float4x4 m = m_xf; m(0, 3) = 0.5f;`): every thread evaluates them, in order with the
// declarations, as the C++ class evaluated them once. `reduced` are the locals the nest reduces,
// whose threads start from the identity instead.
std::set<const Stmt*> StatementsSettingLocals(const std::vector<const Stmt*>& before, const std::set<const VarDecl*>& reduced);

// The statements before and after a kernelND_'s loop nest run on one thread, around the threads of
// the nest: before them (the GPU's <kernel>_Start) and after them (<kernel>_Finish). Every thread
// evaluates the declarations before the nest for itself, and the statements that only set those
// locals (`settingLocals`); any other statement before the nest may not change those locals, and
// neither may the threads (a race on the CPU too). A 'return' before the nest would skip it on the
// CPU but not on the GPU.
bool CheckLoopEnds(Context& c, const std::string& kernel, const std::vector<const Stmt*>& before,
                   const std::vector<const Stmt*>& after, const Stmt* threadBody, const std::set<const Expr*>& reductionTargets,
                   const std::set<const Stmt*>& settingLocals);

// The loop nest of a kernelND_ body: its first top-level `for` whose end is not a constant (a loop
// over kMoments zeroing an array before the nest is a statement before it, run by one thread), or
// its first `for` where every end is a constant. Null when the body has no `for`.
const ForStmt* KernelLoopNest(ASTContext& ctx, const CompoundStmt* body);

struct LoopHeader {
  const VarDecl* var = nullptr;
  const Expr* start = nullptr;
  const Expr* end = nullptr;
  bool inclusive = false;
};

// The one parser of loop headers, for kernels' loop nests, thread loops and leaves' loops: why `fs`
// is not `for (T i = a; i < b; ++i)` (also i++, i += 1, <=; T an integer), or "" when it is, with
// `h` filled in.
std::string LoopShapeProblem(ASTContext& ctx, const ForStmt* fs, LoopHeader& h);

// Accepts `for (T i = a; i < b; ++i)` (also i++, i += 1, <=). Returns false and reports otherwise.
bool ParseLoop(Context& c, const ForStmt* fs, LoopHeader& h, const std::string& kernel);

// Casts the host-side C++ count to the loop variable's range: (end) - (start) [+ 1].
// `expr` as an operand of a wider expression: in parentheses only where an operator inside it
// needs them (`n`, `m_v.size()`, `(n - 1)`).
std::string AsOperand(const std::string& expr);

std::string CountExpr(Context& c, const LoopHeader& h);

// A loop whose iterations run in chunks on all cores (crossrt::ParallelFor, CpuLoops.h): its header
// rewritten in `rw` to run [crt_first, crt_last), and the call's text around the loop, in which its
// bounds are evaluated once (as OpenMP evaluates them). `parallel` is the C++ condition for all
// cores (crt_loop.parallel), `grain` the iterations of a chunk.
struct ChunkedLoop {
  std::string head;  // crossrt::ParallelFor<T>(parallel, begin, end, grain, [&](T crt_first, T crt_last) {
  std::string tail;  // });
};
ChunkedLoop ChunkLoop(clang::Rewriter& rw, clang::ASTContext& ctx, const clang::ForStmt* fs, const LoopHeader& h, const std::string& parallel,
                      const std::string& grain);

}  // namespace crossrt::engine
