// The rewriter of one control function. Its work is split by job: ControlFunctions.cpp (arguments,
// std::vector temporaries, member writes, the visit), ThreadLoops.cpp (loops that call kernels per
// thread), ThreadBodies.cpp (megakernel and wavefront bodies), LibraryCalls.cpp (sort, scan, copy,
// fill), HostReads.cpp (host code that uses what kernels write), MemberSwaps.cpp (swaps of member
// vectors).
#pragma once
#include "analyse/AnalysisContext.h"
#include "analyse/LoopShape.h"

#include <functional>

namespace crossrt::engine {

class ControlRewriter {
public:
  ControlRewriter(Context& c, const CXXMethodDecl* md, const FunctionDecl* def, Control& ctrl)
      : m_c(c), m_md(md), m_def(def), m_ctrl(ctrl),
        m_gpu(c.ctx.getSourceManager(), c.ctx.getLangOpts()), m_cpu(c.ctx.getSourceManager(), c.ctx.getLangOpts()) {}

  void Run();

private:
  // The user's `#pragma omp ...` lines go: on the GPU the loops they parallelise become dispatches,
  // and the CPU class puts its own pragma on each thread loop.
  void RemoveOpenMpPragmas();

  // A pointer argument of a kernel call, as the BufferView the generated code binds.
  std::string BufferArg(const Expr* arg);

  // ---- std::vector locals passed to kernels: std::vector<float> temp(n[, value]); kernel1D_A(temp.data(), ...) ----
  // On the GPU the local gets a device buffer of the generated class (crt_temporaries), sized and
  // filled where the local is declared, as its constructor fills the host's. The host's vector
  // stays (its size() is the buffer's); its elements are never the GPU's, so the control function
  // may only pass data() to kernels and ask for size().

  std::map<const VarDecl*, Control::LocalBuffer> m_temporaries;
  std::set<const DeclRefExpr*> m_temporaryUses;  // the references a kernel argument or size() makes

  const Control::LocalBuffer* Temporary(const VarDecl* vd);

  // A temporary's elements live on the GPU: the host's copy is not theirs to read or write.
  void CheckTemporaryUses();

  // An Image2D argument of a kernel call, as the crossrt::ImageView the generated code binds: the
  // device copy of a parameter of the control function, or of a member.
  std::string ImageArg(const ParmVarDecl* p, const Expr* arg);

  std::string Args(const CXXMemberCallExpr* call, bool skipThreadIds);
  // A member vector's data() given to a kernel's non-const pointer: the kernel may write it, so
  // the control function reads it back (Control::vectorsWritten).
  void WrittenThrough(const Expr* arg);

  // A parameter that some thread loop passes a local's address to holds one value per thread on the
  // GPU; a buffer passed to it elsewhere would be read one element per thread, not as C++ reads it.
  void CheckNotThreadState(const CXXMethodDecl* md, const ParmVarDecl* p, const Expr* arg);

  void Note(const CXXMemberCallExpr* call);

  // ---- thread loops: for (y) for (x) { locals; kernel_A(x, y, &local); for (host) kernel_B(...); } ----
  // Several kernels per thread, sharing per-thread locals (paper 2.1 and 4.4). Both execution modes are
  // recorded: the megakernel (one shader runs the whole body) and wavefront (one dispatch per kernel
  // call, the locals kept in buffers between them); the generated class picks one at run time.

  struct ThreadLoop {
    std::vector<LoopHeader> loops;                 // outermost first
    std::map<const VarDecl*, unsigned> axisOf;     // loop variable -> thread axis
    std::vector<std::pair<const VarDecl*, std::string>> stateBuffers;  // per-thread local -> its wavefront buffer
    std::vector<std::string> bufferArgs;           // host BufferView of each megakernel parameter so far
    std::vector<std::string> cppBufferArgs;        // the same buffers as the C++ passes them (the ISPC class's)
    std::set<const VarDecl*> locals;               // every local of the body (per-thread)
    std::set<const VarDecl*> passed;               // locals some kernel call gets the address of
    std::map<const VarDecl*, std::string> startValues;  // initialised locals the wavefront fills: the host's value
    std::vector<const VarDecl*> outer;             // control-function variables the body reads, first read first
    Kernel mega;                                   // the megakernel, without its kernels' code yet
    std::string hostArgs;                          // ...Cmd arguments of the megakernel after the counts
    std::string counts;                            // ", (w), (h)": threads per axis, x first
    bool megakernelOnly = false;                   // a kernel's result ends a thread's loop: no wavefront form
    // Two kernels' parameters of one name get different buffers (kernel_slicer's test 051): the
    // megakernel, which binds each under the parameter's name, cannot be made; wavefront runs in
    // both modes. Why, and where.
    std::string wavefrontOnly;
    clang::SourceLocation wavefrontOnlyAt;
    bool ok = true;
  };

  // ---- kernel_slicer's per-thread functions: for (i) Run(i, args) with Run(tid, ...) calling kernels ----
  // A thread loop whose body calls such a function is the function's body with its parameters bound
  // to the call's arguments (`m_inlined`): Resolve() reads through them.
  std::map<const ParmVarDecl*, const Expr*> m_inlined;
  const FunctionDecl* m_perThread = nullptr;  // that function's definition; its call may sit in a pass loop
  const Expr* Resolve(const Expr* e) const;
  // The source text of an argument, read through per-thread functions' parameters.
  std::string ResolvedText(const Expr* e) { return m_c.Text(Resolve(e)->getSourceRange()); }

  // Whether `e` is the same for every thread of `tl` (reads no loop variable or per-thread local).
  bool IsUniform(const ThreadLoop& tl, const Expr* e) const;
  // Each variable `e` reads (through per-thread functions' parameters): perThread where its value
  // differs from thread to thread (a loop variable of the thread loop, or one of its locals).
  void ForEachVariable(const ThreadLoop& tl, const Expr* e, const std::function<void(const DeclRefExpr*, const VarDecl*, bool perThread)>& visit) const;
  // A local of a thread loop's body that is a compile-time constant (const uint32_t c = 0xFF;).
  bool IsConstantLocal(const VarDecl* vd) const;
  // A call of the per-thread function being inlined (in a loop of the thread loop's body).
  bool IsPerThreadCall(const CXXMethodDecl* md) const;
  // Variables passed as thread ids to RTV kernels anywhere inside `s`.
  std::set<const VarDecl*> ThreadIdVars(const Stmt* s);

  bool TryThreadLoop(const ForStmt* outerLoop);

  static std::string StateBuffer(const ThreadLoop& tl, const VarDecl* vd);

  void Error(ThreadLoop& tl, SourceLocation loc, const std::string& message, const std::string& hint);
  // The _CPU class's loop over threads (of `nest` loops, `outer` the outermost, its header
  // `outermost`): chunks of its outer loop on all cores (crossrt::ParallelFor), or on this thread
  // while that has been faster (crossrt::ParallelChoice), in a block of its own.
  void ParallelOnCpu(const ForStmt* outer, const LoopHeader& outermost, size_t nest);
  // What ParallelOnCpu writes before and after the loop nest; the outer loop's header, rewritten in
  // m_cpu, runs a chunk. In an _ISPC class's scalar way, `way` names its crossrt::LaneChoice::Run,
  // which the choice of cores is told (a try of this way runs on the cores its verdict ran on).
  std::pair<std::string, std::string> ParallelChoiceAround(const ForStmt* outer, const LoopHeader& outermost, size_t nest,
                                                           const std::string& way = "");

  // Checks that `e` does not depend on the thread (host code and by-value kernel arguments run once
  // for all threads in wavefront mode) and collects the control function's variables it reads.
  void CheckUniform(ThreadLoop& tl, const Expr* e, const std::string& where, bool readOnGpu = true);

  // The GLSL of the thread loop's body (the megakernel) and, alongside, the checks of what may be in it.
  std::string ThreadBodyGlsl(ThreadLoop& tl, KernelPrinter& printer, const Stmt* s, int indent);

  // A kernel call in the thread loop's body, as the megakernel calls the kernel's thread function.
  std::string KernelCallGlsl(ThreadLoop& tl, KernelPrinter& printer, const CXXMemberCallExpr* call);

  // The name kernel md's thread function gives its parameter i (the definition's, as GLSL spells it).
  std::string KernelParamName(const CXXMethodDecl* md, unsigned i) const;
  // A pointer argument of a kernel in a thread loop: in the megakernel, a buffer named as the
  // kernel's parameter (its code refers to that name). Where two kernels name different buffers
  // alike, the GLSL megakernel cannot be made (the loop runs wavefront only: tl.wavefrontOnly), and
  // the ISPC thread loop, which passes each kernel its buffers, names the second one apart. Returns
  // the name the thread loop binds the buffer under, or "".
  std::string AddMegakernelBuffer(ThreadLoop& tl, const CXXMethodDecl* md, const ParmVarDecl* p, const std::string& hostArg,
                                  const std::string& cppArg, SourceLocation loc);

  // The ISPC class: the thread loop's body as an ISPC function of one thread (tl.mega.glslBody) and
  // the control function's loop replaced by chunks of it on all cores, in SIMD lanes. False where
  // the loop stays C++ (three thread axes).
  bool IspcThreadLoop(ThreadLoop& tl, const std::string& body, const ForStmt* outerLoop);
  // The ISPC class: a loop nest around one kernel call, as an export function calling the kernel's
  // thread function over a chunk, and the chunks on all cores in place of the nest. False where
  // the nest stays C++ (three axes, a default or array argument, a kernel returning bool).
  bool IspcRtvNest(const ForStmt* outer, const CXXMemberCallExpr* call, const std::map<unsigned, const LoopHeader*>& axes,
                   const LoopHeader& outermost, size_t nestDepth);
  unsigned m_ispcNests = 0;
  // The ISPC class's control function: in place of the loop nest (its closing ';' included), the
  // chunks in SIMD lanes (`lanes`) or the nest as the _CPU class runs it, whichever has been faster
  // here (crossrt::LaneChoice); `threads` counts the nest's iterations.
  void LanesOrScalarLoop(const ForStmt* loop, const LoopHeader& outermost, size_t nest, const std::string& lanes, const std::string& threads);

  // The wavefront version of the thread loop's body: host loops as written, each kernel call a
  // dispatch over all threads, per-thread locals bound as their buffers.
  std::string ThreadBodyCpp(ThreadLoop& tl, const Stmt* s);

  // for (...) for (...) kernel_X(tidX, tidY, ...): one dispatch of the whole nest.
  bool TryRtvNest(const ForStmt* outer);


  // `m_x = v;` in a control function runs on the host while recording; the kernels recorded
  // around it must see it in order, so the ...Cmd also records an update of the GPU copy (and
  // likewise for the count of a cleared vector that kernels append to).
  void RecordMemberWrite(const Stmt* s);

  // `std::sort(m_v.begin(), m_v.end(), ...)`: the whole of one member vector.
  static bool IsWholeVector(const CallExpr* call);

  // A vector kernels append to has its size on the GPU while the control function records: its host
  // copy is stale until the call returns, so host code may only clear it (or reserve room) and sort
  // all of it, which the GPU does with the count it has.
  void CheckAppendedUses();

  // `m_v.clear();` of a vector kernels append to: the GPU's count restarts at 0 too, in order with
  // the kernels recorded around it. Both go in one block, so a clear that is the body of an `if`
  // or a loop stays one statement.
  void RecordClear(const Stmt* s);

  // ---- host code that uses what kernels write: members, output parameters (HostReads.cpp) ----
  // Finds the host tail: the statements after the last one that records GPU work, when they use
  // something kernels write (m_tail; empty otherwise). Such uses between kernels are errors.
  void FindHostTail();
  // Turns the tail in the ...Cmd body into a lambda it stores (capturing the locals the tail
  // reads), which the generated control function runs after the results are back.
  void MoveHostTail();
  std::vector<const Stmt*> m_tail;
  // Reads of members kernels write, between kernel calls: each becomes a read after
  // crt_Synchronize(crt_cmd, ...), which splits the recording there.
  void SplitAtHostReads();
  // Member vectors on the host before the last kernel call: a read of one kernels write, between
  // them, or any change of one kernels use, is synchronised around the statement that holds it
  // (SynchronizeAround); resizing one, or a use inside a statement that records GPU work too, is an
  // error on Vulkan (the device buffers were sized when the call began). size() and swaps need nothing.
  void CheckHostVectorUses();
  // Marks the outermost statement around `use` that records no GPU work for a crt_Synchronize before
  // it, with `m` read back (download) and uploaded after it (upload); false where there is none.
  bool SynchronizeAround(const MemberExpr* use, const Member& m, bool download, bool upload);
  // Writes those: `crt_Synchronize(crt_cmd, ...); crossrt::DownloadVector(...);` before each statement,
  // `crossrt::UploadVector(...);` after it, and a note of the round trip.
  void SynchronizeHostVectors();
  struct HostVectorSync {
    std::set<std::string> downloads, uploads;
    SourceLocation at;  // the statement's start, for the note
  };
  std::map<const Stmt*, HostVectorSync> m_vectorSyncs;
  std::vector<const Stmt*> m_vectorSyncOrder;  // the statements in the order found (stable output)
  // Vectors the kernels use that the code after the last kernel changes ("hostExpr|name"): uploaded
  // at the end of the host tail.
  std::set<std::string> m_tailUploads;
  std::vector<const MemberExpr*> m_syncReads;
  // Kernel calls that take such a member as an argument: `crt_Synchronize(crt_cmd, ...), kernel1D_XCmd(...)`.
  std::set<const CallExpr*> m_syncCalls;

  // std::swap(m_a, m_b) or m_a.swap(m_b) of std::vector members: on Vulkan their device buffers
  // swap too (MemberSwaps.cpp). False when the call is no such swap.
  bool TrySwap(const CallExpr* call);

  // Another control function would submit its own work while this one is being recorded.
  void CheckNestedControl(const CXXMemberCallExpr* call);

  // ---- library calls on device data: std::exclusive_scan/inclusive_scan, memcpy, std::fill ----

  // A position in device data: `m_v.begin()`, `m_v.end()`, `m_v.data()`, a pointer parameter,
  // each optionally `+ k`.
  struct Position {
    std::string view;      // BufferView expression of the start of the underlying buffer
    std::string key;       // which buffer (member or parameter name)
    std::string offset;    // elements from the start ("" for 0)
    QualType element;
    const Member* vector = nullptr;
    bool isEnd = false;
  };

  std::optional<Position> PositionOf(const Expr* e);

  std::string ViewAt(const Position& p);

  // Elements from `first` to `last`.
  std::optional<std::string> Count(const Position& first, const Position& last);

  void WrittenVector(const Position& p);

  // How a std::sort call orders its elements, as the GPU radix sort needs it.
  struct SortOrder {
    uint32_t keyWord = 0;
    std::string type;  // "Uint", "Int" or "Float"
    bool descending = false;
  };

  // The crossrt::ElementType of a scan element or sort key: "Uint", "Int", "Float", or "" for others.
  static std::string ElementTypeName(QualType t);

  // `a`, `a.key` or `a.inner.key` with `a` a comparator parameter: which parameter, and the key's
  // byte offset in the element.
  std::optional<std::pair<const ParmVarDecl*, uint64_t>> KeyPath(const Expr* e, std::string& keyType);

  // No comparator, std::less<>/std::greater<>, or a lambda `return a.key < b.key;` (or `>`, or
  // with the parameters swapped) over a uint32_t, int or float key.
  std::optional<SortOrder> OrderOf(const CallExpr* call, QualType element, std::string& why);

  // LiteMath's ReduceAddInit(v, n) sizes and zeroes v on the host, as written; its device copy, which
  // kernels' ReduceAdd then add into, is zeroed in order with them.
  bool ReduceAddInit(const CallExpr* call);

  // std::plus<T>(), std::plus<>() or a lambda `[](T a, T b) { return a + b; }`: the scans the GPU runs.
  static bool IsAddition(const Expr* op);

  bool TryLibraryCall(const CallExpr* call);
  // Whether `e` uses a pointer parameter that only host code uses (ControlParam::hostOnly).
  bool MentionsHostOnlyPointer(const Expr* e) const;

  void Visit(const Stmt* s);

  Context& m_c;
  const CXXMethodDecl* m_md;
  const FunctionDecl* m_def;
  Control& m_ctrl;
  Rewriter m_gpu, m_cpu;
  unsigned m_threadLoops = 0;                  // thread loops seen so far (names the megakernels)
  int m_hostLoopDepth = 0;                     // counted loops around the statement of a thread loop being printed
  int m_inlineDepth = -1;                      // m_hostLoopDepth where the per-thread function's body is printed (-1: none)
  std::set<const VarDecl*> m_hostLoopVars;     // counters of loops inside thread loops: the same for all threads
};

}  // namespace crossrt::engine
