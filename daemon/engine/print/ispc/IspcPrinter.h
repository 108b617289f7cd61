// The ISPC printer: how the ISPC backend spells what KernelPrinter walks (IspcCode.cpp writes the
// <Class>_ISPC_kernels.ispc around it). LiteMath.isph names the types and built-ins; functions take
// the class data first (`self`, a pointer to <Class>_Data) and buffers as pointers; values every
// lane of a gang shares are `uniform`; C casts and make_T(...) stand for constructors.
#pragma once
#include "print/KernelPrinter.h"

namespace crossrt::engine {

class IspcPrinter final : public KernelPrinter {
public:
  using KernelPrinter::KernelPrinter;
  std::unique_ptr<KernelPrinter> Sibling(const clang::CXXRecordDecl* cls) const override;

protected:
  std::optional<std::string> DoubleType(clang::QualType t) override;
  std::optional<std::string> SpellType(clang::QualType t, const std::string& gpuType, clang::SourceLocation loc) override;
  std::string StructBody(const clang::RecordDecl* rd) override;
  std::string ConstantQualifier() const override;
  std::string FloatSuffix(const clang::FloatingLiteral* literal) const override;
  std::string FloatInfinity() const override;
  std::string FloatNaN() const override;
  std::string NarrowedDouble(const clang::Expr* sub) override;
  std::string IntegerToReal(const clang::Expr* sub, const clang::Expr* conversion) override;
  std::string ConvertedTo(const std::string& target, const clang::Expr* sub) override;
  std::string ConstructValue(clang::QualType t, const std::string& type, const std::vector<const clang::Expr*>& args,
                             clang::SourceLocation loc) override;
  std::string HalfConstruct(clang::QualType t, const std::vector<const clang::Expr*>& args, clang::SourceLocation loc) override;
  std::string ListConstruct(clang::QualType t, const std::string& base, const std::string& dims, const std::vector<const clang::Expr*>& args,
                            clang::SourceLocation loc) override;
  std::string ArrayValue(const std::string& type, const std::string& list) override;
  std::string FunctionQualifiers(const clang::FunctionDecl* fd) const override;
  std::string ClassDataParameter() const override;
  std::string ClassDataArgument() const override;
  std::string WritableSelf(const std::string& structName) const override;
  std::string ObjectDataStruct(const clang::CXXRecordDecl* cls) const override;
  std::string OwnerParameter(const clang::ParmVarDecl* p) override;
  bool PassesBuffers() const override;
  std::string ArrayValueParamQualifier() const override;
  std::string BufferParameter(const clang::ParmVarDecl* p, const std::string& name) override;
  std::string WritableParam(clang::QualType type, const std::string& name, clang::SourceLocation loc) override;
  std::string MemberAccess(const std::string& name) const override;
  std::string SpecializedAccess(const std::string& name) const override;
  std::string SizeAsInt(const std::string& size) const override;
  std::string EmptyTest(const std::string& size) const override;
  std::string SizeLiteral(uint64_t n) const override;
  std::string ObjectIndex(const clang::Expr* index) override;
  std::string ObjectLocalIndex(const std::string& index) const override;
  std::string AppendFunction(const clang::FieldDecl* field, const clang::CallExpr* call, const std::string& name) override;
  std::string VectorMethod(const clang::FieldDecl* field, const clang::CXXMemberCallExpr* call, const std::string& name) override;
  std::string LibraryCall(const clang::FunctionDecl* fd, const std::vector<std::string>& args, const clang::CallExpr* call,
                          const std::map<std::string, std::string>& same) override;
  std::string BitArgument(const std::string& value, const clang::Expr* arg) const override;
  std::string AtomicOperation(const std::string& name, const std::vector<std::string>& args) override;
  std::string InterlockedCall(const clang::FunctionDecl* fd, const clang::CallExpr* call) override;
  std::string FoldFunction(const std::string& name) const override;
  std::string TexelRead(const clang::CXXOperatorCallExpr* op, const clang::ValueDecl* image) override;
  std::string ImageCall(const clang::ValueDecl* image, const clang::CXXMemberCallExpr* call) override;
  std::string TextureCall(const clang::FieldDecl* array, const clang::Expr* index, const clang::CXXMemberCallExpr* call) override;
  std::string TextureTexel(const clang::FieldDecl* array, const clang::Expr* index, const clang::Expr* coord, clang::SourceLocation loc) override;
  std::string VectorOperator(const clang::CXXOperatorCallExpr* op) override;
  std::string ElementRead(const clang::CXXOperatorCallExpr* op) override;
  std::string WholeStore(const clang::CXXOperatorCallExpr* op) override;
  std::string TexelAssignment(const clang::CXXOperatorCallExpr* op) override;
  std::string Assignment(const clang::BinaryOperator* bo) override;
  std::string PointerRead(const clang::ArraySubscriptExpr* as, const PointerTarget& t) override;
  std::string FieldRead(const clang::MemberExpr* me) override;
  std::string Divisor(const clang::BinaryOperator* bo) override;
  std::string IntegerDivision(const clang::BinaryOperator* bo) override;
  std::string MatrixColumns(const std::string& matrix) const override;
  std::string MatrixObject(const std::string& matrix) const override;
  std::string MatrixRow(const clang::CXXMemberCallExpr* call) override;
  std::string RangeCounter(bool exits) const override;
  std::string LoopInit(const clang::ForStmt* fs, const std::string& init) override;
  std::string ArrayCopy(const clang::VarDecl* vd, const clang::CXXConstructExpr* copy, const std::string& pad) override;
  std::string ThenBranch(const clang::IfStmt* is, int indent) override;
  std::string ForLoop(const clang::ForStmt* fs, int indent) override;
  std::string GangCall(const clang::FunctionDecl* fd, const clang::CallExpr* call) override;
  std::optional<int> FixedGangSize() const override { return std::nullopt; }  // the target's: ISPC folds programCount
  std::string LocalQualifier(const clang::VarDecl* vd) override;
  void ReferenceArgument(const clang::ParmVarDecl* p, const clang::Expr* arg) override;

private:
  // A member of the class data through the data pointer ("self->m_x").
  std::string Member(const std::string& name) const { return dataPointer + "->" + ComposedName(name); }
  // Whether every lane of a gang shares e's value (IspcUniform.cpp), "uniform " for a cast of it,
  // and loop variables the gang runs together.
  bool Uniform(const clang::Expr* e) const;
  bool SharedPlace(const clang::Expr* e) const;
  // CRT_UNIFORM locals (Gang.h): an assignment to one (or to its element) of a value, or at an index, the
  // lanes may not share is reported at the user's line.
  void CheckSharedAssignment(const clang::Expr* target, const clang::Expr* value);
  void SharedValueExpected(const clang::VarDecl* vd, const clang::Expr* where, bool isIndex);
  std::string Variability(const clang::Expr* sub) const;
  const clang::VarDecl* UniformLoop(const clang::ForStmt* fs);
  // What ISPC has no counterpart for (yet): an error with the hint to use the Vulkan or CPU class.
  std::string Unsupported(clang::SourceLocation loc, const std::string& what);
  // The function that builds a struct from its fields (make_S, or crt_make_S beside the user's).
  std::string StructMaker(const clang::RecordDecl* rd) const;
  // No constructor calls in ISPC: make_T(...), a struct's maker, a C cast, a braced list.
  std::string MakeValue(clang::QualType t, const std::string& type, const std::vector<const clang::Expr*>& args, clang::SourceLocation loc);
  // LiteMath's InterlockedAdd3f and ReduceAdd.
  std::string Interlocked(const clang::FunctionDecl* fd, const clang::CallExpr* call);
  // Images (IspcImages.cpp): an image member or parameter; img[p] or img.at(x, y) as an lvalue.
  std::string Image(const clang::ValueDecl* image) const;
  std::string Texel(const clang::Expr* texel);
  // `a op= b` on LiteMath vectors (ISPC overloads no compound assignment), `-v`; `v[i] = a`,
  // `v[i] op= a` with i known only at run time, `m(r, c) = a` ("" for other assignments).
  std::string VectorOperation(const clang::CXXOperatorCallExpr* op);
  std::string ComponentAssignment(const clang::BinaryOperator* bo);
  std::string SharedIndexStore(const clang::BinaryOperator* bo);
  std::string CompoundAssignOnce(const clang::CXXOperatorCallExpr* op);
  // Loads better than a gather (IspcLoads.cpp): a member vector's struct element read whole at a
  // per-lane index, through a helper that loads what the lanes agree on once; a float4, int4 or
  // uint4 read or stored whole through a pointer at a per-lane index (crt_load4, crt_store4), or
  // read as a field of a struct of such rows (crt_load4_field).
  std::string CoherentLoad(const clang::CXXOperatorCallExpr* op);
  std::string ConsecutiveLoad(const clang::ArraySubscriptExpr* as, const PointerTarget& t);
  std::string ConsecutiveFieldLoad(const clang::MemberExpr* me);
  std::string ConsecutiveStore(const clang::CXXOperatorCallExpr* op);
  bool ReadWhole(const clang::Expr* e);  // e's value is copied or passed by value or const reference
  // Where a kernel computes in double (IspcDoubles.cpp).
  bool DeclaredDouble(const clang::Expr* e) const;
  bool InDoubleContext(const clang::Expr* e) const;

  std::vector<std::string> m_coherentLoads;  // struct types with a load helper
  std::set<std::string> m_helpers;           // helpers written so far: crt_<op>_assign_<type>, crt_store_<Struct>
};

}  // namespace crossrt::engine
