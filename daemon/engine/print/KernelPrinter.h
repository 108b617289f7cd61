// The kernel printer: the walk over the C++ (Clang AST) that one kernel reaches, collecting the helper
// functions, structs, members and images it uses. What a target language spells differently is a
// virtual function of KernelPrinter, implemented once per language: glsl/GlslPrinter.h for Vulkan's
// shaders, ispc/IspcPrinter.h for the ISPC backend (Printers.h makes one). Types and layouts are
// GlslTypes.h's: the GPU's types, spelled as GLSL spells them, are the walk's common vocabulary.
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
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace crossrt::engine {

// crossrt::AtomicAdd and the other read-modify-write operations of Atomics.h.
bool IsCrossrtAtomic(const clang::FunctionDecl* fd);
// crossrt::GangSize, AnyLane, AllLanes, FirstLane and MinOverLanes of Gang.h; a local declared
// CRT_UNIFORM (annotated "crossrt::uniform"), which the gang shares.
bool IsGangFunction(const clang::FunctionDecl* fd);
bool IsUniformLocal(const clang::VarDecl* vd);
// A data member declared CRT_SPECIALIZE (Specialize.h; annotated "crossrt::specialize"), which GLSL
// reads as a specialization constant.
bool IsSpecializedMember(const clang::FieldDecl* field);

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
// structs and constants the kernel needs, in the order a shading language accepts (callees before
// callers). Abstract: the language's spellings are the pure virtual functions below.
class KernelPrinter {
public:
  KernelPrinter(clang::ASTContext& ctx, const clang::CXXRecordDecl* cls, Reporter& reporter);
  virtual ~KernelPrinter() = default;
  // A printer of the same language for another class (the traversal a composed object calls back).
  virtual std::unique_ptr<KernelPrinter> Sibling(const clang::CXXRecordDecl* cls) const = 0;

  // Names that print differently: reduction members -> their per-thread accumulator, pointer params.
  std::map<const clang::ValueDecl*, std::string> renames;
  // Pointer parameters that hold one value per thread (a local of a control function's thread
  // loop passed as &local): the GPU passes the value itself, so *p, p->f and p[0] print as p, p.f.
  std::set<const clang::ValueDecl*> valueParams;
  // The kernel's Image2D reference parameters (the definition's): images bound per call, used in
  // the kernel's own body as member images are.
  OrderedSet<const clang::ValueDecl*> imageParams;
  // The values every thread of a group shares (a kernel's scalar parameters, the outer loops'
  // variables of a 2D or 3D nest), as the analysis found them; a language whose threads run in
  // lockstep declares them so (and loop variables found uniform from them).
  std::set<const clang::ValueDecl*> uniformValues;

  // Composition (paper 3.6). In a kernel's printer: interfaces with an implementation
  // ("ISceneObject" -> "BVHScene"); a call through a member holding one prints as
  // `<member>_<method>(...)` and is recorded in Uses().composedCalls for the implementation's
  // printer, which runs on the implementation's AST afterwards.
  std::map<std::string, std::string> compositions;
  // In an implementation's printer: the prefix its members and functions get ("m_pAccelStruct_").
  std::string composedPrefix;
  // A member's name with that prefix; a generated name keeps the reserved prefix first
  // (crt_m_nodes_size -> crt_m_pAccelStruct_m_nodes_size, as the class data names it).
  std::string ComposedName(const std::string& name) const {
    return name.rfind("crt_", 0) == 0 ? "crt_" + composedPrefix + name.substr(4) : composedPrefix + name;
  }
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
  // print/Owner.cpp. In an object's printer: the traversal's printer. The parameter is left out of
  // the GPU's functions, and what is read through it (scene->m_values[i], scene->Helper(...))
  // prints as the traversal's own code does, under the traversal's prefix and in its Uses().
  KernelPrinter* owner = nullptr;
  // A parameter (or the type of one) pointing at the class this printer's `owner` prints, or, with
  // no owner, at this printer's own class: an argument the GPU leaves out.
  static bool PointsTo(clang::QualType t, const clang::CXXRecordDecl* cls);
  bool IsOwnerParam(const clang::ParmVarDecl* p) const;
  bool PassesSelf(const clang::ParmVarDecl* p, const clang::Expr* arg) const;  // `this` for such a parameter
  const clang::CXXRecordDecl* Class() const { return m_class; }

  // The class data's struct name ("<Class>_Data"). A composed implementation's printer names the
  // class's (dataStruct): its members are the class's too.
  std::string dataStruct;
  std::string DataStruct() const;
  // What points at the class data where a function is passed it (an object's method: its traversal
  // parameter).
  std::string dataPointer = "self";

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
  // A local's name in the printed code: SafeName's, or a new one where it shadows a name of an
  // enclosing scope, which ISPC warns of (analyse/Shadowing.cpp).
  std::string LocalName(const clang::VarDecl* vd);

protected:
  // What a pointer in a kernel points at (Pointers.cpp).
  struct PointerTarget {
    std::string array;   // the array it points into (as the printed code names it), or "" for one variable
    std::string offset;  // its element offset in `array` ("" is 0)
    std::string value;   // one variable: its lvalue
    bool local = false;  // the array is a local one (a copy of a helper cannot reach it)
    std::string perThread;  // a thread loop's local passed by address (for messages)
  };

  // ---- what each language spells differently (glsl/GlslPrinter.cpp, ispc/IspcPrinter.cpp) ----
  // Types: a double where the language has one (else nullopt: refused); a GPU type (GLSL's
  // spelling, GlslTypes.h) as the language spells it (nullopt, reported, where it has none).
  virtual std::optional<std::string> DoubleType(clang::QualType t) = 0;
  virtual std::optional<std::string> SpellType(clang::QualType t, const std::string& gpuType, clang::SourceLocation loc) = 0;
  // A struct's fields and closing brace (and whatever builds one), after `struct Name {`.
  virtual std::string StructBody(const clang::RecordDecl* rd) = 0;
  virtual std::string ConstantQualifier() const = 0;  // before a constant's type
  virtual std::string FloatSuffix(const clang::FloatingLiteral* literal) const = 0;
  virtual std::string FloatInfinity() const = 0;  // a constant expression for +inf (and for NaN)
  virtual std::string FloatNaN() const = 0;
  // Conversions: a double narrowed to float, an integer made real (`conversion` is the cast node),
  // a value converted to a GPU type (`target`, GLSL's spelling) other than bool.
  virtual std::string NarrowedDouble(const clang::Expr* sub) = 0;
  virtual std::string IntegerToReal(const clang::Expr* sub, const clang::Expr* conversion) = 0;
  virtual std::string ConvertedTo(const std::string& target, const clang::Expr* sub) = 0;
  // Construction of a value of type t (spelled `type`) from args, past copies (Construct); of
  // LiteMath's half2 and half4; of an array or struct from an initializer list; a std::array's
  // elements (`list`) as a value of type `type`.
  virtual std::string ConstructValue(clang::QualType t, const std::string& type, const std::vector<const clang::Expr*>& args,
                                     clang::SourceLocation loc) = 0;
  virtual std::string HalfConstruct(clang::QualType t, const std::vector<const clang::Expr*>& args, clang::SourceLocation loc) = 0;
  virtual std::string ListConstruct(clang::QualType t, const std::string& base, const std::string& dims,
                                    const std::vector<const clang::Expr*>& args, clang::SourceLocation loc) = 0;
  virtual std::string ArrayValue(const std::string& type, const std::string& list) = 0;
  // Functions: what precedes function fd's return type (fd's noinline, say); the class data as the
  // first parameter of the class's methods and as the first argument of their calls ("" where it is
  // global); a struct's method's writable `self`; an object's data struct; the traversal passed to
  // an object's method ("" where it is left out); whether buffers are passed to helpers (else each
  // copy of a helper indexes the buffers it is bound to), and such a buffer's parameter; a writable
  // parameter.
  virtual std::string FunctionQualifiers(const clang::FunctionDecl* fd) const = 0;
  virtual std::string ClassDataParameter() const = 0;
  virtual std::string ClassDataArgument() const = 0;
  virtual std::string WritableSelf(const std::string& structName) const = 0;
  virtual std::string ObjectDataStruct(const clang::CXXRecordDecl* cls) const = 0;
  virtual std::string OwnerParameter(const clang::ParmVarDecl* p) = 0;
  virtual bool PassesBuffers() const = 0;
  // A helper's parameter declared as a const array (const float boxMin[3]): the caller's array, whole;
  // before its declaration, what the language needs there ("const " where it passes the address).
  bool IsArrayValueParam(const clang::ParmVarDecl* p) const;
  virtual std::string ArrayValueParamQualifier() const = 0;
  virtual std::string BufferParameter(const clang::ParmVarDecl* p, const std::string& name) = 0;
  virtual std::string WritableParam(clang::QualType type, const std::string& name, clang::SourceLocation loc) = 0;
  // Members of the class data, by name; a vector's size as an int; whether a size is 0; a size as
  // an unsigned literal; the index of an element of a vector of objects (its expression, or the text
  // a local pointing at one holds).
  virtual std::string MemberAccess(const std::string& name) const = 0;
  virtual std::string SpecializedAccess(const std::string& name) const = 0;  // a CRT_SPECIALIZE member's value
  virtual std::string SizeAsInt(const std::string& size) const = 0;
  virtual std::string EmptyTest(const std::string& size) const = 0;
  virtual std::string SizeLiteral(uint64_t n) const = 0;
  virtual std::string ObjectIndex(const clang::Expr* index) = 0;
  virtual std::string ObjectLocalIndex(const std::string& index) const = 0;
  // push_back to a member vector: the function `name` that appends (written once per vector); a
  // member vector's other methods where the language handles them itself ("" to go on).
  virtual std::string AppendFunction(const clang::FieldDecl* field, const clang::CallExpr* call, const std::string& name) = 0;
  virtual std::string VectorMethod(const clang::FieldDecl* field, const clang::CXXMemberCallExpr* call, const std::string& name) = 0;
  // Calls: library functions (`same`: those spelled as GLSL spells them); an unsigned conversion
  // of a bit builtin's argument; crossrt::Atomic* with its printed arguments; LiteMath's
  // InterlockedAdd and ReduceAdd; the function std::min and std::max of a list fold with.
  virtual std::string LibraryCall(const clang::FunctionDecl* fd, const std::vector<std::string>& args, const clang::CallExpr* call,
                                  const std::map<std::string, std::string>& same) = 0;
  virtual std::string BitArgument(const std::string& value, const clang::Expr* arg) const = 0;
  virtual std::string AtomicOperation(const std::string& name, const std::vector<std::string>& args) = 0;
  virtual std::string InterlockedCall(const clang::FunctionDecl* fd, const clang::CallExpr* call) = 0;
  virtual std::string FoldFunction(const std::string& name) const = 0;
  // Images and arrays of textures: a texel read (img[p]), the image's methods, a texture's.
  virtual std::string TexelRead(const clang::CXXOperatorCallExpr* op, const clang::ValueDecl* image) = 0;
  virtual std::string ImageCall(const clang::ValueDecl* image, const clang::CXXMemberCallExpr* call) = 0;
  virtual std::string TextureCall(const clang::FieldDecl* array, const clang::Expr* index, const clang::CXXMemberCallExpr* call) = 0;
  virtual std::string TextureTexel(const clang::FieldDecl* array, const clang::Expr* index, const clang::Expr* coord, clang::SourceLocation loc) = 0;
  // Operators the language prints its own way, or "" for the common spelling: LiteMath's vector
  // operators; an element of a member vector; a store through a pointer; an assignment to a texel
  // (an operator call or built in); any assignment; an element read through a pointer; a field of
  // an element (a[i].f) read through a pointer or from a member vector.
  virtual std::string VectorOperator(const clang::CXXOperatorCallExpr* op) = 0;
  virtual std::string ElementRead(const clang::CXXOperatorCallExpr* op) = 0;
  virtual std::string WholeStore(const clang::CXXOperatorCallExpr* op) = 0;
  virtual std::string TexelAssignment(const clang::CXXOperatorCallExpr* op) = 0;
  virtual std::string Assignment(const clang::BinaryOperator* bo) = 0;
  virtual std::string PointerRead(const clang::ArraySubscriptExpr* as, const PointerTarget& t) = 0;
  virtual std::string FieldRead(const clang::MemberExpr* me) = 0;
  // The divisor of an integer division or remainder; a LiteMath matrix's columns (as an expression
  // and as the object of a method); a matrix's row (get_row), or "" for the common spelling.
  virtual std::string Divisor(const clang::BinaryOperator* bo) = 0;
  // A 32-bit integer division or remainder (a / b, a % b) in a language's own form, or "" for the
  // common spelling.
  virtual std::string IntegerDivision(const clang::BinaryOperator* bo) = 0;
  virtual std::string MatrixColumns(const std::string& matrix) const = 0;
  virtual std::string MatrixObject(const std::string& matrix) const = 0;
  virtual std::string MatrixRow(const clang::CXXMemberCallExpr* call) = 0;
  // Statements: a range-for's counter type (`exits`: the body may leave early); a for loop's
  // init statement; a copy of a std::array into a local (the statements after its declaration,
  // or "" where arrays copy whole).
  virtual std::string RangeCounter(bool exits) const = 0;
  virtual std::string LoopInit(const clang::ForStmt* fs, const std::string& init) = 0;
  virtual std::string ArrayCopy(const clang::VarDecl* vd, const clang::CXXConstructExpr* copy, const std::string& pad) = 0;
  // An if's then-branch, as printed after its `if (...)` line (ISPC marks some `unmasked`).
  virtual std::string ThenBranch(const clang::IfStmt* is, int indent);
  // A counted loop, whole (ISPC runs a loop whose lanes share out its items `unmasked`).
  virtual std::string ForLoop(const clang::ForStmt* fs, int indent);
  // The gang (Gang.h): crossrt::GangSize, AnyLane, AllLanes, FirstLane, MinOverLanes and AllLanesOn; what a
  // local's declaration starts with besides `const` (ISPC's `uniform` for a CRT_UNIFORM local).
  virtual std::string GangCall(const clang::FunctionDecl* fd, const clang::CallExpr* call) = 0;
  // The gang's size where the language fixes it (GLSL: 1), else nullopt (ISPC: its target's).
  virtual std::optional<int> FixedGangSize() const = 0;
  virtual std::string LocalQualifier(const clang::VarDecl* vd) = 0;
  // An argument bound to a helper's non-const reference parameter (ISPC reports a CRT_UNIFORM local
  // there: a lane's reference cannot bind the gang's variable).
  virtual void ReferenceArgument(const clang::ParmVarDecl*, const clang::Expr*) {}

  // ---- the walk ----
  // The per-thread value parameter `e` reads (*p, p[0]; with pointerItself, p), or null.
  const clang::ValueDecl* ValueParamOf(const clang::Expr* e, bool pointerItself = false) const;
  std::string Call(const clang::CallExpr* call);
  // What a condition on crossrt::GangSize() is where the language fixes the size (`GangSize() == 4
  // && ...` is false in GLSL), or nullopt: an `if` prints only its branch taken (Calls.cpp).
  std::optional<bool> GangCondition(const clang::Expr* e) const;
  std::string IfCondition(const clang::Expr* cond);
  std::string Builtin(const clang::FunctionDecl* fd, const std::vector<std::string>& args, const clang::CallExpr* call);
  std::string Construct(clang::QualType t, const std::vector<const clang::Expr*>& args, clang::SourceLocation loc);
  std::string Literal(const clang::Expr* e);
  std::string Cast(clang::QualType to, const clang::Expr* sub);
  // Image2D members and parameters: the image an expression names (m_img, or a kernel's image
  // parameter), or null; a texel expression (img[p], img.at(x, y)) as its image (and coordinate);
  // whether an image's texel type can be stored; the sampler a sample() call uses.
  const clang::ValueDecl* ImageOf(const clang::Expr* e) const;
  const clang::ValueDecl* ImageTexel(const clang::Expr* e, std::string* coord = nullptr);
  std::optional<ImageFormat> UsableImage(const clang::ValueDecl* image, clang::SourceLocation use);  // reports why not
  const clang::FieldDecl* SampledWith(const clang::ValueDecl* image, const ImageFormat& format, const clang::CXXMemberCallExpr* call);
  // Arrays of textures: the array of an element expression (m_textures[i]) and its index.
  const clang::FieldDecl* TextureElement(const clang::Expr* e, const clang::Expr** index = nullptr);
  bool UsableTextures(const clang::FieldDecl* array, clang::SourceLocation use);  // reports why not
  std::string AtomicCall(const clang::FunctionDecl* fd, const clang::CallExpr* call);
  std::string AtomicTargetProblem(const clang::Expr* target) const;
  std::string EmitAppend(const clang::FieldDecl* field, const clang::CallExpr* call);
  // `T& r = a[i].f;` in a kernel or helper: the text its uses print as (GLSL has no references), when
  // the referred lvalue stays the same through r's scope (no side effects; its indices' variables
  // not written after r is declared). Else nullopt, and `why` says why not (Pointers.cpp).
  std::optional<std::string> ReferenceAlias(const clang::VarDecl* vd, const clang::DeclStmt* decl, std::string& why);
  // A function's body (a helper's, a lambda's), printed apart from the kernel's thread body.
  std::string FunctionBody(const clang::Stmt* body);
  // ---- lambdas in kernels (Lambdas.cpp) ----
  // `f(args)` where f is a local lambda, or a lambda called where it is written: a call of the
  // lambda as a function of its own (EmitLambda), its captures passed after the arguments.
  std::string LambdaCall(const clang::CXXOperatorCallExpr* op);
  std::string EmitLambda(const clang::LambdaExpr* lambda, const std::string& name);
  std::map<const clang::LambdaExpr*, std::string> m_lambdaNames;
  // A user function as a function of the kernel's code, once; with `bufferBindings` (parameter
  // index -> buffer), a copy of it whose pointer parameters index those buffers from an offset (see
  // Pointers.cpp). With `structSelf`, a member function of that plain struct: the object comes
  // first, as `self`.
  std::string EmitHelper(const clang::FunctionDecl* fd, clang::SourceLocation callLoc, bool composedEntry = false,
                         const std::map<unsigned, std::string>& bufferBindings = {}, const clang::CXXRecordDecl* structSelf = nullptr);
  // ---- plain structs' member functions, operators and constructors (Structs.cpp) ----
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
  // ---- pointers (Pointers.cpp; PointerTarget is above) ----
  std::optional<PointerTarget> Pointer(const clang::Expr* e);  // what e points at; nullopt (reported) when unknown
  std::string Pointee(const PointerTarget& t, const clang::Expr* index, clang::SourceLocation loc);  // *p, p[index]
  std::vector<std::string> HelperArgs(const clang::FunctionDecl* fd, const clang::CallExpr* call, std::map<unsigned, std::string>& bindings);
  std::string PointerLocal(const clang::VarDecl* vd, const std::string& pad);  // T* p = ...;
  std::string TextOf(const clang::Expr* e) const;
  std::map<const clang::ValueDecl*, PointerTarget> m_pointers;  // pointer locals and helper parameters in scope
  std::map<const clang::ValueDecl*, const clang::FieldDecl*> m_objectLocals;  // `T* p = m_v[i]`: p holds i (ObjectLocal)
  std::map<const clang::VarDecl*, std::string> m_localNames;  // LocalName's answers
  std::set<std::string> m_emittedCopies;                         // helpers bound to buffers, by name
  const clang::Expr* m_fieldBase = nullptr;                      // the base of the field access being printed
  std::vector<std::string> m_reduceAddVectors;                   // member vectors with a ReduceAdd function

public:
  bool PointerIsValueOnly(const clang::FunctionDecl* fn, const clang::ParmVarDecl* p);

protected:
  // A member of this printer's class as `this->f` prints (its prefix, its Uses); OwnerMember and
  // OwnerCall print `scene->f` and `scene->Helper(...)` through the owner (Owner.cpp).
  std::string SelfMember(const clang::MemberExpr* me, const clang::FieldDecl* field);
  const clang::ParmVarDecl* OwnerParamOf(const clang::Expr* e) const;
  std::string OwnerCall(const clang::CXXMemberCallExpr* call);
  std::string ComposedCall(const clang::CXXMemberCallExpr* call);
  std::string VirtualCall(const clang::CXXMemberCallExpr* call);
  void NeedStruct(const clang::RecordDecl* rd);
  std::string NeedConstant(const clang::VarDecl* vd);  // its name in the printed code
  std::string ConstantName(const clang::VarDecl* vd) const;
  std::string Fail(clang::SourceLocation loc, const std::string& message, const std::string& hint);

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
