// The GLSL printer: how Vulkan's compute and ray tracing shaders spell what KernelPrinter walks.
// Buffers, images and the class data are globals of the shader (its binding blocks), so functions
// take no class data; GLSL has constructors (vec3(x)), inout parameters and no pointers.
#pragma once
#include "print/KernelPrinter.h"

namespace crossrt::engine {

class GlslPrinter final : public KernelPrinter {
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
  std::string IntegerDivision(const clang::BinaryOperator*) override { return ""; }  // GLSL divides in the vector
  std::string MatrixColumns(const std::string& matrix) const override;
  std::string MatrixObject(const std::string& matrix) const override;
  std::string MatrixRow(const clang::CXXMemberCallExpr* call) override;
  std::string RangeCounter(bool exits) const override;
  std::string LoopInit(const clang::ForStmt* fs, const std::string& init) override;
  std::string ArrayCopy(const clang::VarDecl* vd, const clang::CXXConstructExpr* copy, const std::string& pad) override;
  std::string GangCall(const clang::FunctionDecl* fd, const clang::CallExpr* call) override;
  std::optional<int> FixedGangSize() const override { return 1; }  // a thread is a gang of one
  std::string LocalQualifier(const clang::VarDecl* vd) override;

private:
  // A texel stored whole (imageStore) of a storage image.
  std::string ImageStore(const clang::Expr* lhs, const std::string& value, const clang::Expr* whole);
};

}  // namespace crossrt::engine
