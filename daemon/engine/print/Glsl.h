// The GLSL printer: C++ (Clang AST) to GLSL for the code one kernel reaches, collecting the helper
// functions, structs, members and images it uses. Types and layouts are in GlslTypes.h.
#pragma once
#include "Diagnostics.h"
#include "print/GlslTypes.h"
#include "Model.h"
#include "OrderedSet.h"

#include <clang/AST/ASTContext.h>
#include <clang/AST/DeclCXX.h>
#include <clang/AST/Expr.h>
#include <clang/AST/ExprCXX.h>
#include <clang/AST/Stmt.h>

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace crossrt::engine {

// crossrt::AtomicAdd and the other read-modify-write operations of Atomics.h.
bool IsCrossrtAtomic(const clang::FunctionDecl* fd);

// The polymorphic class a shared_ptr, unique_ptr or plain pointer type points to, or null.
const clang::CXXRecordDecl* PolymorphicPointee(clang::QualType type);
// `m_v[i]->Method(...)` through a member std::vector of pointers to a polymorphic class: the vector
// (and in `index`, the expression i), or null for other calls. Also `p->Method(...)` through a local
// `T* p = m_v[i];` or `= m_v[i].get();` (ObjectLocal): then `index` is p, which kernels hold as i.
const clang::FieldDecl* VirtualCallTarget(const clang::CXXMemberCallExpr* call, const clang::Expr** index = nullptr);
// A local pointer to an element of such a vector, `T* p = m_v[i]` or `= m_v[i].get()`: the vector
// (and in `index`, the expression i), or null for other locals.
const clang::FieldDecl* ObjectLocal(const clang::VarDecl* local, const clang::Expr** index = nullptr);

// What the code a printer printed uses, recorded while printing: the facts the passes read
// afterwards (which buffers, images and helpers a kernel binds and calls) instead of parsing the
// text. Iterated in the order the printer met them.
struct PrintedUses {
  // Members declared std::vector that the code reaches, plain members it reads.
  OrderedSet<const clang::FieldDecl*> memberVectors, plainMembers;
  // Where it reads a member vector's size (a kernel may not read what it appends to).
  std::multimap<const clang::FieldDecl*, clang::SourceLocation> sizeReads;
  // Where it reads the size of a vector of objects (the class data holds it with the vector's
  // tags, so the kernel must also call through it).
  std::multimap<const clang::FieldDecl*, clang::SourceLocation> objectSizeReads;
  // Image2D members and parameters it loads or stores texels of (storage images), samples
  // (textures), and the Sampler members it samples with.
  OrderedSet<const clang::ValueDecl*> loadedImages, storedImages, sampledImages;
  OrderedSet<const clang::FieldDecl*> samplers;
  OrderedSet<const clang::ValueDecl*> sizedImages;  // whose width() or height() it reads
  OrderedSet<std::pair<const clang::ValueDecl*, const clang::FieldDecl*>> samplePairs;  // (image, sampler)
  // Arrays of textures (std::vector<LiteImage::Texture2D<T>> members) it samples or reads.
  OrderedSet<const clang::FieldDecl*> textureArrays;
  // Helper functions it reaches (their writes to members matter too).
  std::vector<const clang::FunctionDecl*> helpers;
  // Calls through composed interfaces, as (holder member, method).
  std::set<std::pair<std::string, std::string>> composedCalls;
  // Virtual calls `m_objects[i]->Method(...)` through a std::vector of pointers to a polymorphic
  // class, as (vector member, interface method), and each such call in printing order.
  OrderedSet<std::pair<const clang::FieldDecl*, const clang::CXXMethodDecl*>> virtualCalls;
  std::vector<const clang::CXXMemberCallExpr*> virtualCallSites;
  // crossrt::Atomic* calls: buffers must be coherent (GL_KHR_memory_scope_semantics).
  bool atomics = false;
  // Floats added atomically (LiteMath's InterlockedAdd, ReduceAdd): GL_EXT_shader_atomic_float.
  bool floatAtomics = false;
  // Member vectors emptied (clear() or resize(0)) in single-thread code.
  OrderedSet<const clang::FieldDecl*> emptiedVectors;
};

// Prints the code one kernel reaches. One instance per kernel; it collects the helper functions,
// structs and constants the kernel needs, in an order GLSL accepts (callees before callers).
class GlslPrinter {
public:
  GlslPrinter(clang::ASTContext& ctx, const clang::CXXRecordDecl* cls, Reporter& reporter);

  // Names that print differently: reduction members -> their per-thread accumulator, pointer params.
  std::map<const clang::ValueDecl*, std::string> renames;
  // Pointer parameters that hold one value per thread (a local of a control function's thread
  // loop passed as &local): the GPU passes the value itself, so *p, p->f and p[0] print as p, p.f.
  std::set<const clang::ValueDecl*> valueParams;
  // The kernel's Image2D reference parameters (the definition's): images bound per call, used in
  // the kernel's own body as member images are.
  OrderedSet<const clang::ValueDecl*> imageParams;
  // ISPC: the values every lane of a gang shares (a kernel's scalar parameters, the outer loops'
  // variables of a 2D or 3D nest), and loop variables found uniform from them (IspcUniformLoop).
  std::set<const clang::ValueDecl*> uniformValues;
  bool IspcUniform(const clang::Expr* e) const;

  // Composition (paper 3.6). In a kernel's printer: interfaces with an implementation
  // ("ISceneObject" -> "BVHScene"); a call through a member holding one prints as
  // `<member>_<method>(...)` and is recorded in Uses().composedCalls for the implementation's
  // printer, which runs on the implementation's AST afterwards.
  std::map<std::string, std::string> compositions;
  // In an implementation's printer: the prefix its members and functions get ("m_pAccelStruct_").
  std::string composedPrefix;
  // Prints the implementation of an interface method, called from kernels as <prefix><name>.
  std::string EmitComposedMethod(const clang::CXXMethodDecl* method);

  // Statements printed as other text (each line indented as the statement): the loops over leaves
  // of a traversal that the ray tracing hardware runs instead (virtual functions, level 3).
  std::map<const clang::Stmt*, std::string> replacedStatements;
  // In an implementation's printer ("object mode"): the class whose methods are printed; its members
  // read from the parameter `self` of type <Class>_Data, and its methods take `self` first.
  const clang::CXXRecordDecl* selfClass = nullptr;

  // The composed implementation passed to an object's method (paper 3.10: a traversal's leaf
  // call `m_geom[g]->Intersect(ray, info, hit, this)` with `Intersect(..., const BVHRT* scene)`),
  // GlslOwner.cpp. In an object's printer: the traversal's printer. The parameter is left out of
  // the GPU's functions, and what is read through it (scene->m_values[i], scene->Helper(...))
  // prints as the traversal's own code does, under the traversal's prefix and in its Uses().
  GlslPrinter* owner = nullptr;
  // A parameter (or the type of one) pointing at the class this printer's `owner` prints, or, with
  // no owner, at this printer's own class: an argument the GPU leaves out.
  static bool PointsTo(clang::QualType t, const clang::CXXRecordDecl* cls);
  bool IsOwnerParam(const clang::ParmVarDecl* p) const;
  bool PassesSelf(const clang::ParmVarDecl* p, const clang::Expr* arg) const;  // `this` for such a parameter
  const clang::CXXRecordDecl* Class() const { return m_class; }

  // ISPC instead of GLSL (the ISPC backend, IspcCode.cpp): LiteMath's type names, make_T(...)
  // constructors, C casts, references for inout parameters, members read through `self` (a pointer
  // to <Class>_Data, which the class's methods take first), and the built-ins of LiteMath.isph.
  bool ispc = false;
  // The ISPC data struct's name and the text of a member through it ("self->m_x"). A composed
  // implementation's printer names the class's (ispcDataStruct): its members are the class's too.
  std::string ispcDataStruct;
  std::string DataStruct() const;
  std::string IspcMember(const std::string& name) const { return ispcSelf + "->" + composedPrefix + name; }
  std::string ispcSelf = "self";  // what points at the class data (an object's method: its traversal parameter)

  // Printing statements one thread runs (before or after a kernel's loop nest): a member vector that
  // kernels append to may be emptied there (its count restarts).
  bool singleThread = false;
  // The thread function returns a value (a kernel_ function returning bool).
  bool threadReturnsValue = false;

  // What the code printed so far uses.
  const PrintedUses& Uses() const { return m_uses; }
  // Size reads recorded while printing single-thread code (where they are allowed) are forgotten.
  void RestoreSizeReads(std::multimap<const clang::FieldDecl*, clang::SourceLocation> reads) { m_uses.sizeReads = std::move(reads); }

  std::string Expr(const clang::Expr* e);
  std::string Stmt(const clang::Stmt* s, int indent);
  // `for (T x : a)` over a fixed-size array (local, member or field) or a member std::vector of the
  // class: a counted loop whose body starts by declaring x as a's element.
  std::string RangeFor(const clang::CXXForRangeStmt* rf, int indent);
  // The thread's function body: `continue` at loop depth 0 ends the thread (becomes `return`).
  // In a loop-holding kernel (loopBody), `return` would end every later iteration on the CPU,
  // which threads cannot do: it is reported.
  std::string ThreadBody(const clang::Stmt* body, int indent, bool loopBody);
  std::optional<std::string> Type(clang::QualType t, clang::SourceLocation loc);
  std::string Declare(clang::QualType t, const std::string& name, clang::SourceLocation loc);

  // Structs the code needs (above the buffer blocks), then constants and helper functions (below),
  // one by one so that composed code can be merged ahead of a kernel's; PreludeTypes joins the structs.
  std::string PreludeTypes() const;
  const std::vector<GlslDecl>& Structs() const { return m_structs; }
  const std::vector<GlslDecl>& Constants() const { return m_constants; }
  const std::vector<std::string>& Functions() const { return m_functions; }
  // Structs declared once for the whole class (the class-data block needs them): not emitted again.
  std::set<std::string> predeclaredStructs;
  static std::string SafeName(const std::string& name);  // renames GLSL keywords

private:
  // The per-thread value parameter `e` reads (*p, p[0]; with pointerItself, p), or null.
  const clang::ValueDecl* ValueParamOf(const clang::Expr* e, bool pointerItself = false) const;
  std::string Call(const clang::CallExpr* call);
  std::string Builtin(const clang::FunctionDecl* fd, const std::vector<std::string>& args, const clang::CallExpr* call);
  std::string IspcBuiltin(const clang::FunctionDecl* fd, const std::vector<std::string>& args, const clang::CallExpr* call,
                          const std::map<std::string, std::string>& same);
  std::string Construct(clang::QualType t, const std::vector<const clang::Expr*>& args, clang::SourceLocation loc);
  std::string IspcConstruct(clang::QualType t, const std::string& type, const std::vector<const clang::Expr*>& args, clang::SourceLocation loc);
  std::string HalfConstruct(clang::QualType t, const std::vector<const clang::Expr*>& args, clang::SourceLocation loc);
  std::string Literal(const clang::Expr* e);
  std::string Cast(clang::QualType to, const clang::Expr* sub);
  // Image2D members and parameters: the image an expression names (m_img, or a kernel's image
  // parameter), or null; a texel expression (img[p], img.at(x, y)) as its image (and coordinate);
  // loads, stores and the image's other calls.
  const clang::ValueDecl* ImageOf(const clang::Expr* e) const;
  const clang::ValueDecl* ImageTexel(const clang::Expr* e, std::string* coord = nullptr);
  std::optional<ImageFormat> UsableImage(const clang::ValueDecl* image, clang::SourceLocation use);  // reports why not
  const clang::FieldDecl* SampledWith(const clang::ValueDecl* image, const ImageFormat& format, const clang::CXXMemberCallExpr* call);
  std::string ImageStore(const clang::Expr* lhs, const std::string& value, const clang::Expr* whole);
  std::string ImageCall(const clang::ValueDecl* image, const clang::CXXMemberCallExpr* call);
  // Arrays of textures: the array of an element expression (m_textures[i]) and its index; calls on
  // an element (sample, width, height) and texel reads (m_textures[i][p]).
  const clang::FieldDecl* TextureElement(const clang::Expr* e, const clang::Expr** index = nullptr);
  std::string TextureCall(const clang::FieldDecl* array, const clang::Expr* index, const clang::CXXMemberCallExpr* call);
  std::string TextureTexel(const clang::FieldDecl* array, const clang::Expr* index, const clang::Expr* coord, clang::SourceLocation loc);
  bool UsableTextures(const clang::FieldDecl* array, clang::SourceLocation use);  // reports why not
  std::string AtomicCall(const clang::FunctionDecl* fd, const clang::CallExpr* call);
  std::string InterlockedCall(const clang::FunctionDecl* fd, const clang::CallExpr* call);  // LiteMath's InterlockedAdd, ReduceAdd
  std::string IspcImage(const clang::ValueDecl* image) const;              // ISPC: an image member or parameter
  std::string IspcTexel(const clang::Expr* texel);                          // ISPC: img[p], img.at(x, y) as an lvalue
  std::string IspcImageCall(const clang::ValueDecl* image, const clang::CXXMemberCallExpr* call);  // ISPC: width(), sample(), ...
  std::string IspcTextureCall(const clang::FieldDecl* array, const clang::Expr* index, const clang::CXXMemberCallExpr* call);
  std::string IspcTextureTexel(const clang::FieldDecl* array, const clang::Expr* index, const clang::Expr* coord, clang::SourceLocation loc);
  const clang::VarDecl* IspcUniformLoop(const clang::ForStmt* fs) const;
  std::string IspcInterlockedCall(const clang::FunctionDecl* fd, const clang::CallExpr* call);  // the same in ISPC
  std::string AtomicTargetProblem(const clang::Expr* target) const;
  std::string EmitAppend(const clang::FieldDecl* field, const clang::CallExpr* call);
  // `T& r = a[i].f;` in a kernel or helper: the text its uses print as (GLSL has no references), when
  // the referred lvalue stays the same through r's scope (no side effects; its indices' variables
  // not written after r is declared). Else nullopt, and `why` says why not (GlslPointers.cpp).
  std::optional<std::string> ReferenceAlias(const clang::VarDecl* vd, const clang::DeclStmt* decl, std::string& why);
  // A parameter the callee may write: GLSL's inout, ISPC's reference.
  std::string WritableParam(clang::QualType type, const std::string& name, clang::SourceLocation loc);
  // A function's body (a helper's, a lambda's), printed apart from the kernel's thread body.
  std::string FunctionBody(const clang::Stmt* body);
  // ---- lambdas in kernels (GlslLambdas.cpp) ----
  // `f(args)` where f is a local lambda, or a lambda called where it is written: a call of the
  // lambda as a function of its own (EmitLambda), its captures passed after the arguments.
  std::string LambdaCall(const clang::CXXOperatorCallExpr* op);
  std::string EmitLambda(const clang::LambdaExpr* lambda, const std::string& name);
  std::map<const clang::LambdaExpr*, std::string> m_lambdaNames;
  // A user function as a GLSL function, once; with `bufferBindings` (parameter index -> buffer), a copy
  // of it whose pointer parameters index those buffers from an offset (see GlslPointers.cpp).
  // With `structSelf`, a member function of that plain struct: the object comes first, as `self`.
  std::string EmitHelper(const clang::FunctionDecl* fd, clang::SourceLocation callLoc, bool composedEntry = false,
                         const std::map<unsigned, std::string>& bufferBindings = {}, const clang::CXXRecordDecl* structSelf = nullptr);
  // ---- plain structs' member functions, operators and constructors (GlslStructs.cpp) ----
  bool IsPlainStruct(const clang::CXXRecordDecl* rd) const;
  std::string FunctionName(const clang::FunctionDecl* fd, const clang::CXXRecordDecl* structSelf) const;
  std::string StructMethodCall(const clang::CXXMemberCallExpr* call);
  std::string StructOperatorCall(const clang::CXXOperatorCallExpr* op);
  bool IsStructOperator(const clang::CXXOperatorCallExpr* op) const;
  std::string ConstructorCall(const clang::CXXConstructorDecl* ctor, const std::vector<const clang::Expr*>& args, clang::SourceLocation loc);
  bool IsUserConstructor(const clang::CXXConstructorDecl* ctor) const;
  std::string MatrixMethodCall(const clang::CXXMemberCallExpr* call);
  const clang::CXXRecordDecl* m_structSelf = nullptr;  // printing a member function of this struct: `this` is `self`
  bool m_inConstructor = false;                         // ... a constructor, which returns `self`
  // ---- pointers (GlslPointers.cpp) ----
  struct PointerTarget {
    std::string array;   // the array it points into (as GLSL names it), or "" for one variable
    std::string offset;  // its element offset in `array` ("" is 0)
    std::string value;   // one variable: its GLSL lvalue
    bool local = false;  // the array is a local one (a copy of a helper cannot reach it)
    std::string perThread;  // a thread loop's local passed by address (for messages)
  };
  std::optional<PointerTarget> Pointer(const clang::Expr* e);  // what e points at; nullopt (reported) when unknown
  std::string Pointee(const PointerTarget& t, const clang::Expr* index, clang::SourceLocation loc);  // *p, p[index]
  std::vector<std::string> HelperArgs(const clang::FunctionDecl* fd, const clang::CallExpr* call, std::map<unsigned, std::string>& bindings);
  std::string PointerLocal(const clang::VarDecl* vd, const std::string& pad);  // T* p = ...;
  std::string TextOf(const clang::Expr* e) const;
  std::map<const clang::ValueDecl*, PointerTarget> m_pointers;  // pointer locals and helper parameters in scope
  std::map<const clang::ValueDecl*, const clang::FieldDecl*> m_objectLocals;  // `T* p = m_v[i]`: p holds i (ObjectLocal)
  std::set<std::string> m_emittedCopies;                         // helpers bound to buffers, by name
  std::vector<std::string> m_coherentLoads;                      // struct types with an ISPC load helper
  std::set<std::string> m_ispcHelpers;                       // ISPC helpers written so far: crt_<op>_assign_<type>, crt_store_<Struct>
  const clang::Expr* m_fieldBase = nullptr;                      // the base of the field access being printed
  std::vector<std::string> m_reduceAddVectors;                   // member vectors with a ReduceAdd function

public:
  bool PointerIsValueOnly(const clang::FunctionDecl* fn, const clang::ParmVarDecl* p);

private:
  // A member of this printer's class as `this->f` prints (its prefix, its Uses); OwnerMember and
  // OwnerCall print `scene->f` and `scene->Helper(...)` through the owner (GlslOwner.cpp).
  std::string SelfMember(const clang::MemberExpr* me, const clang::FieldDecl* field);
  const clang::ParmVarDecl* OwnerParamOf(const clang::Expr* e) const;
  std::string OwnerCall(const clang::CXXMemberCallExpr* call);
  std::string ComposedCall(const clang::CXXMemberCallExpr* call);
  std::string VirtualCall(const clang::CXXMemberCallExpr* call);
  void NeedStruct(const clang::RecordDecl* rd);
  std::string IspcStructMaker(const clang::RecordDecl* rd) const;
  std::string NeedConstant(const clang::VarDecl* vd);  // its GLSL name
  std::string ConstantName(const clang::VarDecl* vd) const;
  std::string Fail(clang::SourceLocation loc, const std::string& message, const std::string& hint);
  // What ISPC has no counterpart for (yet): an error with the hint to use the Vulkan or CPU class.
  std::string IspcFail(clang::SourceLocation loc, const std::string& what);
  // `a op= b` on LiteMath vectors (ISPC overloads no compound assignment), `-v`.
  std::string IspcVectorOperator(const clang::CXXOperatorCallExpr* op);
  // `v[i] = a`, `v[i] op= a` with i known only at run time, `m(r, c) = a`; "" for other assignments.
  std::string IspcComponentAssignment(const clang::BinaryOperator* bo);
  // A member vector's struct element read whole at a per-lane index, through a helper that loads what
  // the lanes agree on once (IspcLoads.cpp); "" where a plain subscript is printed.
  std::string IspcCoherentLoad(const clang::CXXOperatorCallExpr* op);
  // A float4, int4 or uint4 read whole through a pointer at a per-lane index, through LiteMath.isph's
  // crt_load4 (vector loads where the lanes read consecutive elements, IspcLoads.cpp); "" otherwise.
  std::string IspcConsecutiveLoad(const clang::ArraySubscriptExpr* as, const PointerTarget& t);
  std::string IspcConsecutiveStore(const clang::CXXOperatorCallExpr* op);
  std::string IspcVariability(const clang::Expr* sub) const;
  std::string IspcCompoundAssignOnce(const clang::CXXOperatorCallExpr* op);
  // IspcDoubles.cpp: where a kernel computes in double on ISPC.
  bool IspcDeclaredDouble(const clang::Expr* e) const;
  bool IspcInDoubleContext(const clang::Expr* e) const;
  bool ReadWhole(const clang::Expr* e);  // e's value is copied or passed by value or const reference

  clang::ASTContext& m_ctx;
  const clang::CXXRecordDecl* m_class;
  Reporter& m_reporter;
  int m_loopDepth = 0;
  bool m_inThreadBody = false;
  bool m_inLoopBody = false;
  std::vector<GlslDecl> m_structs, m_constants;  // in emission order
  std::vector<std::string> m_functions;
  std::set<const clang::Decl*> m_emitted, m_inProgress;
  PrintedUses m_uses;
};

}  // namespace crossrt::engine
