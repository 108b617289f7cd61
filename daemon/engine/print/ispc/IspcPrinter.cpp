// ISPC's spellings of what KernelPrinter walks: types and padded structs, C casts and make_T(...),
// the class data through `self`, uniform values, appends on the host, vectors' operators (IspcPrinter.h).
#include "print/ispc/IspcPrinter.h"
#include "print/ispc/IspcTypes.h"
#include "analyse/AstQueries.h"
#include "print/GlslTypes.h"
#include "print/PrinterParts.h"

#include <clang/AST/ParentMapContext.h>
#include <clang/AST/RecordLayout.h>

#include <map>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

std::string IspcPrinter::Unsupported(SourceLocation loc, const std::string& what) {
  return Fail(loc, what + " is not translated to ISPC yet", "translate this class with BACKEND cpu (all cores, no SIMD lanes) or vulkan");
}

// ISPC: the function that builds a struct from its fields, make_S, or crt_make_S where the user's
// code has a make_S of its own (which then comes along as the user wrote it).
std::string IspcPrinter::StructMaker(const RecordDecl* rd) const {
  const std::string maker = "make_" + rd->getName().str();
  auto& idents = m_ctx.Idents;
  for (const DeclContext* dc : {rd->getDeclContext()->getRedeclContext(), static_cast<const DeclContext*>(m_ctx.getTranslationUnitDecl())})
    for (auto* d : dc->lookup(&idents.get(maker)))
      if (isa<FunctionDecl>(d)) return "crt_" + maker;
  return maker;
}

// "uniform " where an ISPC cast's operand is one value for all lanes: a cast with no variability
// takes its operand's, and ISPC warns of such a cast where it is an argument (its operator overloads
// included). Else "" (varying, the default).
std::string IspcPrinter::Variability(const clang::Expr* sub) const { return Uniform(sub) ? "uniform " : ""; }

// ISPC has no constructor calls: LiteMath's make_float3(...), the struct's make_S(...) that NeedStruct
// writes, a cast of a scalar, and an initializer list of an array (which only a declaration takes).
std::string IspcPrinter::MakeValue(QualType t, const std::string& type, const std::vector<const clang::Expr*>& args, SourceLocation loc) {
  if (IsLiteMathType(t, "half4") || IsLiteMathType(t, "half2") || (args.size() == 1 && IsLiteMathType(args[0]->getType(), "half4")))
    return HalfConstruct(t, args, loc);
  auto list = [&](const std::vector<std::string>& items) {
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i];
    return out;
  };
  std::vector<std::string> values;
  for (auto* a : args) values.push_back(Expr(a));
  if (auto* arr = dyn_cast<ConstantArrayType>(t.getCanonicalType().getTypePtr())) {
    if (values.empty())
      values.assign(arr->getSize().getZExtValue(), Construct(arr->getElementType(), {}, loc));
    return "{" + list(values) + "}";
  }
  auto* rd = t.getCanonicalType()->getAsCXXRecordDecl();
  if (!rd && values.empty())  // a scalar's zero: a literal, varying or uniform as its use needs
    return type == "float" ? "0.0f" : type == "uint" ? "0u" : type == "bool" ? "false" : type == "int" ? "0" : "((" + type + ")0)";
  if (!rd) return "((" + type + ")(" + values[0] + "))";
  if (values.empty() && !IsLiteMathType(t))  // value-initialised struct: default member initialisers, else zero
    for (auto* f : rd->fields())
      values.push_back(f->hasInClassInitializer() && f->getInClassInitializer() ? Expr(f->getInClassInitializer())
                                                                                : Construct(f->getType(), {}, loc));
  return (rd && !IsLiteMathType(t) ? StructMaker(rd) : "make_" + type) + "(" + list(values) + ")";
}

// LiteMath's vector and matrix operators that ISPC's struct operators cannot be: compound assignment
// (written out, the target printed twice), negation (LiteMath.isph's neg), a component by index (a
// constant: the field; else LiteMath.isph's crt_get), a matrix's column m[i] and element m(r, c).
std::string IspcPrinter::VectorOperation(const CXXOperatorCallExpr* op) {
  if (op->getNumArgs() == 0 || !IsLiteMathType(op->getArg(0)->getType().getNonReferenceType())) return "";
  const auto kind = op->getOperator();
  if (std::string store = ConsecutiveStore(op); !store.empty()) return store;
  const bool matrix = IsLiteMathType(op->getArg(0)->getType().getNonReferenceType(), "float4x4") ||
                      IsLiteMathType(op->getArg(0)->getType().getNonReferenceType(), "float3x3");
  if (kind == OO_Minus && op->getNumArgs() == 1 && matrix) return "((" + Expr(op->getArg(0)) + ") * -1.0f)";
  if (kind == OO_Minus && op->getNumArgs() == 1) return "neg(" + Expr(op->getArg(0)) + ")";
  if (kind == OO_Plus && op->getNumArgs() == 1) return Expr(op->getArg(0));
  if ((kind == OO_PlusEqual || kind == OO_MinusEqual || kind == OO_StarEqual || kind == OO_SlashEqual) && op->getNumArgs() == 2) {
    if (op->getArg(0)->HasSideEffects(m_ctx, /*IncludePossibleEffects=*/false)) {  // v[k++] += a: the address once
      if (std::string once = CompoundAssignOnce(op); !once.empty()) return once;
      return Unsupported(op->getBeginLoc(), "compound assignment to a vector whose address has side effects, other than an element of a buffer, member vector or local array,");
    }
    const std::string target = Expr(op->getArg(0)), spelling = getOperatorSpelling(kind);
    return target + " = " + target + " " + spelling.substr(0, 1) + " (" + Expr(op->getArg(1)) + ")";
  }
  if (kind == OO_Subscript && matrix) return "(" + Expr(op->getArg(0)) + ").m_col[" + Expr(op->getArg(1)) + "]";  // column i
  if (kind == OO_Call && matrix && op->getNumArgs() == 3)  // m(row, col)
    return "crt_get((" + Expr(op->getArg(0)) + ").m_col[" + Expr(op->getArg(2)) + "], " + Expr(op->getArg(1)) + ")";
  if (kind == OO_Subscript) {
    clang::Expr::EvalResult index;
    if (!op->getArg(1)->EvaluateAsInt(index, m_ctx))
      return "crt_get(" + Expr(op->getArg(0)) + ", " + Expr(op->getArg(1)) + ")";  // LiteMath.isph: a select per component
    if (index.Val.getInt().getExtValue() < 0 || index.Val.getInt().getExtValue() > 3)
      return Unsupported(op->getBeginLoc(), "a vector's component by an index out of its range");
    return "(" + Expr(op->getArg(0)) + ")." + std::string(1, "xyzw"[index.Val.getInt().getExtValue()]);
  }
  if (kind == OO_EqualEqual || kind == OO_ExclaimEqual) return Unsupported(op->getBeginLoc(), "comparison of whole vectors");
  return "";
}

// v[i] = a and v[i] op= a, where v is a LiteMath vector and i known only at run time, and a matrix's
// m(r, c) = a: ISPC's structs have no subscript, so LiteMath.isph's crt_set writes the component
// (v and i printed twice for op=).
std::string IspcPrinter::ComponentAssignment(const BinaryOperator* bo) {
  auto* op = dyn_cast<CXXOperatorCallExpr>(bo->getLHS()->IgnoreParenImpCasts());
  if (!op) return "";
  std::string v, i;
  const auto glsl = GlslTypeOf(op->getArg(0)->getType().getNonReferenceType());
  clang::Expr::EvalResult index;
  if (op->getOperator() == OO_Call && op->getNumArgs() == 3 && glsl && glsl->rfind("mat", 0) == 0) {  // m(row, col) = a
    v = "(" + Expr(op->getArg(0)) + ").m_col[" + Expr(op->getArg(2)) + "]";
    i = Expr(op->getArg(1));
  } else if (op->getOperator() == OO_Subscript && op->getNumArgs() == 2 && glsl && glsl->find("vec") != std::string::npos &&
             !op->getArg(1)->EvaluateAsInt(index, m_ctx)) {
    v = Expr(op->getArg(0));
    i = Expr(op->getArg(1));
  } else {
    return "";
  }
  if (bo->getOpcode() == BO_Assign) return "crt_set(" + v + ", " + i + ", " + Expr(bo->getRHS()) + ")";
  for (unsigned a = 0; a < op->getNumArgs(); ++a)
    if (op->getArg(a)->HasSideEffects(m_ctx, false))
      return Unsupported(bo->getBeginLoc(), "compound assignment to a vector's component whose vector or index has side effects");
  const std::string spelling = BinaryOperator::getOpcodeStr(BinaryOperator::getOpForCompoundAssignment(bo->getOpcode())).str();
  return "crt_set(" + v + ", " + i + ", crt_get(" + v + ", " + i + ") " + spelling + " (" + Expr(bo->getRHS()) + "))";
}

// C's double, which ISPC has: double, double[2][3].
std::optional<std::string> IspcPrinter::DoubleType(QualType t) {
  std::string dims;
  for (QualType a = t.getNonReferenceType(); auto* arr = dyn_cast<ConstantArrayType>(a.getCanonicalType().getTypePtr()); a = arr->getElementType())
    dims += "[" + std::to_string(arr->getSize().getZExtValue()) + "]";
  return "double" + dims;
}

std::optional<std::string> IspcPrinter::SpellType(QualType t, const std::string& gpuType, SourceLocation loc) {
  if (gpuType.find("bvec") != std::string::npos) {
    Unsupported(loc, "type '" + t.getAsString(m_ctx.getPrintingPolicy()) + "'");
    return std::nullopt;
  }
  return IspcTypeName(gpuType);
}

// The padding from byte `at` to byte `to`: 32-bit words where it can be, bytes where it must. A
// varying struct assigned under a mask (a value returned in an `if`) stores each member masked.
// AVX2 has masked stores of 32- and 64-bit elements only, so ISPC stores a byte array one lane and
// one byte at a time, a branch each: 96 such stores for the 12 padding bytes of PathTracer's
// LightSample or BsdfSample, where 3 words are 3 vector stores (PathTracer_ISPC's lanes went from
// 0.95x of PathTracer_CPU's speed to 1.22x with avx2 on an AMD EPYC, Zen 5).
static void Pad(std::ostream& os, uint64_t at, uint64_t to, unsigned& pads) {
  const uint64_t wordsFrom = std::min(to, (at + 3) / 4 * 4), wordsTo = std::max(wordsFrom, to / 4 * 4);
  if (wordsFrom > at) os << "  uint8 crt_pad" << pads++ << "[" << (wordsFrom - at) << "];\n";
  if (wordsTo > wordsFrom) os << "  uint32 crt_pad" << pads++ << "[" << (wordsTo - wordsFrom) / 4 << "];\n";
  if (to > wordsTo) os << "  uint8 crt_pad" << pads++ << "[" << (to - wordsTo) << "];\n";
}

// ISPC aligns every member of these types to 4 bytes; C++ may align more (LiteMath's float4 to
// 16): explicit padding puts each field where C++ has it, so that buffers are shared as they are.
// A struct without arrays gets its maker, make_S(fields...).
std::string IspcPrinter::StructBody(const RecordDecl* rd) {
  std::ostringstream os;
  const ASTRecordLayout& layout = m_ctx.getASTRecordLayout(rd);
  uint64_t at = 0;
  unsigned index = 0, pads = 0;
  std::string params, assigns;
  bool constructible = true;
  for (auto* f : rd->fields()) {
    const uint64_t offset = layout.getFieldOffset(index++) / 8;
    if (offset > at) Pad(os, at, offset, pads);
    os << "  " << Declare(f->getType(), f->getName().str(), f->getLocation()) << ";\n";
    at = offset + m_ctx.getTypeSizeInChars(f->getType()).getQuantity();
    constructible &= !f->getType()->isArrayType();
    auto type = Type(f->getType(), f->getLocation());
    params += (params.empty() ? "" : ", ") + type.value_or("int") + " " + SafeName(f->getName().str());
    assigns += " r." + SafeName(f->getName().str()) + " = " + SafeName(f->getName().str()) + ";";
  }
  const uint64_t size = layout.getSize().getQuantity();
  if (size > at) Pad(os, at, size, pads);
  os << "};\n";
  if (constructible)
    os << "static inline " << rd->getName().str() << " " << StructMaker(rd) << "(" << params << ")\n{\n  "
       << rd->getName().str() << " r;" << assigns << "\n  return r;\n}\n";
  return os.str();
}

std::string IspcPrinter::ConstantQualifier() const { return "static const uniform "; }  // one per object file, not a global symbol

// ISPC's double literal where the kernel computes in double (an unsuffixed one is a float).
std::string IspcPrinter::FloatSuffix(const FloatingLiteral* literal) const { return InDoubleContext(literal) ? "d" : ""; }
// LiteMath.isph's constants: ISPC folds 1.0 / 0.0 too, but warns of it wherever it is written.
std::string IspcPrinter::FloatInfinity() const { return "crt_infinity"; }
std::string IspcPrinter::FloatNaN() const { return "crt_nan"; }

std::string IspcPrinter::NarrowedDouble(const clang::Expr* sub) {
  return DeclaredDouble(sub) ? "((float)(" + Expr(sub) + "))" : Expr(sub);
}

std::string IspcPrinter::IntegerToReal(const clang::Expr* sub, const clang::Expr* conversion) {
  if (conversion && InDoubleContext(conversion)) return "((double)(" + Expr(sub) + "))";
  return "((" + Variability(sub) + "float)(" + Expr(sub) + "))";
}

// C's cast of a scalar, LiteMath's make_T of a vector.
std::string IspcPrinter::ConvertedTo(const std::string& target, const clang::Expr* sub) {
  const std::string name = IspcTypeName(target);
  if (target.find("vec") != std::string::npos) return "make_" + name + "(" + Expr(sub) + ")";
  return "((" + Variability(sub) + name + ")(" + Expr(sub) + "))";
}

std::string IspcPrinter::ConstructValue(QualType t, const std::string& type, const std::vector<const clang::Expr*>& args, SourceLocation loc) {
  return MakeValue(t, type, args, loc);
}

// The ISPC class appends on the host, under its lock, as the _CPU class's threads do: no capacity
// to reserve. A gang hands over its active lanes' values at once, in lane order.
std::string IspcPrinter::AppendFunction(const FieldDecl* field, const CallExpr* call, const std::string& name) {
  const std::string vector = field->getNameAsString();
  QualType element;
  IsStdVector(field->getType(), &element);
  std::ostringstream os;
  const std::string cls = DataStruct().substr(0, DataStruct().size() - std::string("_Data").size());
  const std::string type = Type(element, call->getBeginLoc()).value_or("uint"), host = "crt_" + cls + "_append_" + vector;
  os << "// " << vector << ".push_back(value): " << cls << "_ISPC::crt_IspcAppend_" << vector << " appends the values (C++, under a lock)\n"
     << "extern \"C\" void " << host << "(int8 *uniform owner, const uniform " << type << " *uniform values, uniform int count);\n\n"
     << "// " << vector << ".push_back(value) from the active lanes, in lane order\n"
     << "static void " << name << "(uniform " << DataStruct() << " *uniform self, " << type << " value)\n"
     << "{\n"
     << "  uniform " << type << " lanes[programCount], packed[programCount];\n"
     << "  lanes[programIndex] = value;\n"
     << "  uniform int count = 0;\n"
     << "  foreach_active (lane)\n"
     << "    packed[count++] = lanes[lane];\n"
     << "  " << host << "(self->crt_owner, packed, count);\n"
     << "}\n";
  m_functions.push_back(os.str());
  return name;
}

// A helper the user marked noinline ([[gnu::noinline]], __attribute__((noinline))) stays a call on
// ISPC too: a cold path kept out of a kernel's hot code. Every other helper is inline, as ISPC
// inlines anyway.
std::string IspcPrinter::FunctionQualifiers(const clang::FunctionDecl* fd) const {
  return fd && fd->hasAttr<clang::NoInlineAttr>() ? "static noinline " : "static inline ";
}

std::string IspcPrinter::ClassDataParameter() const { return "uniform " + DataStruct() + " *uniform self"; }

std::string IspcPrinter::ClassDataArgument() const { return "self"; }

std::string IspcPrinter::WritableSelf(const std::string& structName) const { return structName + " &self"; }

std::string IspcPrinter::ObjectDataStruct(const CXXRecordDecl* cls) const { return IspcObjectStruct(cls->getQualifiedNameAsString()); }

// The traversal passed to an object's method: the class data, which holds the traversal's.
std::string IspcPrinter::OwnerParameter(const ParmVarDecl* p) {
  return "uniform " + owner->DataStruct() + " *uniform " + SafeName(p->getNameAsString());
}

bool IspcPrinter::PassesBuffers() const { return true; }

// `const float boxMin[3]` is a pointer in ISPC, as in C: a const array (a const local struct's field)
// converts only to a pointer to const.
std::string IspcPrinter::ArrayValueParamQualifier() const { return "const "; }

std::string IspcPrinter::BufferParameter(const ParmVarDecl* p, const std::string& name) {
  const QualType pt = p->getType();
  auto element = Type(pt->getPointeeType().getUnqualifiedType(), p->getLocation());
  return std::string(pt->getPointeeType().isConstQualified() ? "const " : "") + "uniform " + (element ? *element : "int") + " *uniform " + name + ", ";
}

std::string IspcPrinter::ObjectIndex(const clang::Expr* index) { return "((" + Variability(index) + "uint)(" + Expr(index) + "))"; }

std::string IspcPrinter::ObjectLocalIndex(const std::string& index) const { return "(uint)(" + index + ")"; }

std::string IspcPrinter::MemberAccess(const std::string& name) const { return Member(name); }

// CRT_SPECIALIZE changes what the GPU compiles: ISPC reads the member from the class data, as any other.
std::string IspcPrinter::SpecializedAccess(const std::string& name) const { return Member(name); }

std::string IspcPrinter::SizeAsInt(const std::string& size) const { return size; }

std::string IspcPrinter::EmptyTest(const std::string& size) const { return "(" + size + " == 0)"; }

std::string IspcPrinter::SizeLiteral(uint64_t n) const { return std::to_string(n); }

std::string IspcPrinter::TexelAssignment(const CXXOperatorCallExpr*) { return ""; }  // ISPC's texels are lvalues

std::string IspcPrinter::Assignment(const BinaryOperator* bo) {
  CheckSharedAssignment(bo->getLHS(), bo->getRHS());
  if (std::string store = SharedIndexStore(bo); !store.empty()) return store;
  return ComponentAssignment(bo);
}

// `p[k] = v` or `p[k] += v` through a buffer pointer, or into a member vector (m_v[k]), at an index
// every lane shares, of a value that may differ between them (`if (i == 0) a_data[0] = v.x;`): ISPC
// takes p[0] for one uniform element, to which a varying value does not convert. The lanes that run
// the statement store the last one's value (crt_store_last: the original's last iteration's), or
// add all of theirs (crt_add_lanes), as one statement; through a pointer with an offset (a row,
// `float* row = a_out + y * w`), where the lanes' elements may differ, each stores its own.
// "" otherwise.
std::string IspcPrinter::SharedIndexStore(const BinaryOperator* bo) {
  if (bo->getOpcode() != BO_Assign && bo->getOpcode() != BO_AddAssign) return "";
  const clang::Expr* target = bo->getLHS()->IgnoreParenImpCasts();
  const auto glsl = GlslTypeOf(target->getType().getUnqualifiedType());
  if (!glsl || (*glsl != "float" && *glsl != "int" && *glsl != "uint" && *glsl != "double") || Uniform(bo->getRHS())) return "";
  // A statement of its own (its value is not used), with any temporaries' cleanups (std::min's).
  auto parents = m_ctx.getParents(*static_cast<const clang::Stmt*>(bo));
  while (parents.size() == 1 && parents[0].get<ExprWithCleanups>()) parents = m_ctx.getParents(*parents[0].get<ExprWithCleanups>());
  if (parents.size() != 1 || parents[0].get<clang::Expr>() || !parents[0].get<clang::Stmt>()) return "";
  std::string array, index;
  if (auto* as = dyn_cast<ArraySubscriptExpr>(target)) {
    auto* decay = dyn_cast<ImplicitCastExpr>(as->getBase()->IgnoreParens());
    if ((decay && decay->getCastKind() == CK_ArrayToPointerDecay) || !as->getBase()->getType()->isPointerType() || !Uniform(as->getIdx())) return "";
    auto t = Pointer(as->getBase());
    if (!t || !t->value.empty() || t->local || t->array.empty()) return "";
    array = t->array;
    index = t->offset.empty() ? Expr(as->getIdx()) : t->offset + " + " + Expr(as->getIdx());  // (an offset may differ per lane)
  } else if (auto* op = dyn_cast<CXXOperatorCallExpr>(target); op && op->getOperator() == OO_Subscript && op->getNumArgs() == 2) {
    const FieldDecl* f = ThisMemberField(op->getArg(0));
    if (!f || !IsStdVector(f->getType()) || !Uniform(op->getArg(1))) return "";
    array = Expr(op->getArg(0));
    index = Expr(op->getArg(1));
  } else {
    return "";
  }
  const std::string type = IspcTypeName(*glsl);
  return std::string(bo->getOpcode() == BO_Assign ? "crt_store_last(" : "crt_add_lanes(") + array + ", (varying int)(" + index + "), (varying " + type +
         ")(" + Expr(bo->getRHS()) + "))";
}

// ISPC divides the masked-off lanes too, whose divisor may be 0 (a masked gather's): a per-lane
// integer divisor goes through crt_divisor (LiteMath.isph), which gives those lanes 1.
std::string IspcPrinter::Divisor(const BinaryOperator* bo) {
  const bool guarded = bo->getRHS()->getType()->isIntegerType() && !bo->getRHS()->isIntegerConstantExpr(m_ctx) && !Uniform(bo->getRHS());
  return guarded ? "crt_divisor(" + Expr(bo->getRHS()) + ")" : Expr(bo->getRHS());
}

// x86 has no vector instruction for integer division, and ISPC divides a value per lane by
// another, or by a uniform variable, one lane at a time (idiv). A 32-bit quotient is exact through
// doubles, in the vector (LiteMath.isph's crt_div and crt_rem): 5.4x as fast with avx2, 8.9x with
// avx512skx, on an AMD EPYC (Zen 5). A constant divisor, which ISPC turns into a multiplication, and
// uniform operands keep the operator; so do 64-bit integers, which a double does not hold.
std::string IspcPrinter::IntegerDivision(const BinaryOperator* bo) {
  const QualType t = bo->getType().getCanonicalType();
  if (!t->isIntegerType() || t->isBooleanType() || m_ctx.getTypeSize(t) != 32) return "";
  if (bo->getRHS()->isIntegerConstantExpr(m_ctx) || (Uniform(bo->getLHS()) && Uniform(bo->getRHS()))) return "";
  const std::string type = t->isSignedIntegerType() ? "varying int" : "varying uint";  // (a uniform operand cast so, not to unbound int)
  return std::string(bo->getOpcode() == BO_Div ? "crt_div" : "crt_rem") + "((" + type + ")(" + Expr(bo->getLHS()) + "), (" + type + ")(" +
         Expr(bo->getRHS()) + "))";
}

std::string IspcPrinter::MatrixColumns(const std::string& matrix) const { return matrix + ".m_col"; }  // LiteMath.isph's matrices are structs of columns

std::string IspcPrinter::MatrixObject(const std::string& matrix) const { return "(" + matrix + ").m_col"; }

std::string IspcPrinter::VectorOperator(const CXXOperatorCallExpr* op) { return VectorOperation(op); }

std::string IspcPrinter::ElementRead(const CXXOperatorCallExpr* op) { return CoherentLoad(op); }

std::string IspcPrinter::WholeStore(const CXXOperatorCallExpr* op) { return ConsecutiveStore(op); }  // LiteMath's vectors: VectorOperation

std::string IspcPrinter::PointerRead(const ArraySubscriptExpr* as, const PointerTarget& t) { return ConsecutiveLoad(as, t); }

std::string IspcPrinter::FieldRead(const MemberExpr* me) { return ConsecutiveFieldLoad(me); }

std::string IspcPrinter::ArrayValue(const std::string&, const std::string& list) { return "{" + list + "}"; }

std::string IspcPrinter::ListConstruct(QualType t, const std::string& base, const std::string&, const std::vector<const clang::Expr*>& args,
                                       SourceLocation loc) {
  return MakeValue(t, base, args, loc);
}

std::string IspcPrinter::RangeCounter(bool exits) const { return exits ? "int " : "uniform int "; }

// A counted loop the gang runs once (IspcUniform.cpp): its variable is uniform.
std::string IspcPrinter::LoopInit(const ForStmt* fs, const std::string& init) {
  const VarDecl* shared = UniformLoop(fs);
  if (!shared) return init;
  uniformValues.insert(shared);
  return "uniform " + init;
}

// ISPC arrays do not copy whole (C's rule): element by element.
std::string IspcPrinter::ArrayCopy(const VarDecl* vd, const CXXConstructExpr* cons, const std::string& pad) {
  const std::string name = LocalName(vd);
  uint64_t n = 0;
  IsStdArray(vd->getType(), nullptr, &n);
  return pad + "for (uniform int crt_i = 0; crt_i < " + std::to_string(n) + "; ++crt_i)  // a copy of " + TrimmedSourceText(m_ctx, cons->getArg(0)->getSourceRange()) +
         "\n" + pad + "  " + name + "[crt_i] = " + Expr(cons->getArg(0)) + "[crt_i];\n";
}

// push_back appends through the host (AppendFunction); the class's other vector methods are not translated.
std::string IspcPrinter::VectorMethod(const FieldDecl* field, const CXXMemberCallExpr* call, const std::string& name) {
  if (name == "push_back" && call->getNumArgs() == 1 && composedPrefix.empty()) return EmitAppend(field, call) + "(self, " + Expr(call->getArg(0)) + ")";
  return Unsupported(call->getBeginLoc(), "std::vector::" + name + " of a member in a kernel");
}

std::string IspcPrinter::MatrixRow(const CXXMemberCallExpr* call) {
  return "transpose(" + Expr(call->getImplicitObjectArgument()) + ").m_col[" + Expr(call->getArg(0)) + "]";
}

// LiteMath's half2 and half4 hold their 16-bit floats two per uint (the crt_ conversions of
// LiteMath.isph); float4(h) and to_float4(h) unpack them. Built through a float2 or float4 of the values.
std::string IspcPrinter::HalfConstruct(QualType t, const std::vector<const clang::Expr*>& args, SourceLocation loc) {
  const bool four = IsLiteMathType(t, "half4");
  if (IsLiteMathType(t, "float4")) return "crt_half4_to_float4(" + Expr(args[0]) + ")";  // float4(half4)
  std::vector<std::string> a;
  for (auto* arg : args) a.push_back(Expr(arg));
  const std::string to = four ? "crt_float4_to_half4(" : "crt_float2_to_half2(", vec = four ? "make_float4(" : "make_float2(";
  if (args.empty()) return four ? "make_uint2(0u)" : "0u";
  if (args.size() == 1 && IsLiteMathType(args[0]->getType(), four ? "float4" : "float2")) return to + a[0] + ")";
  if (args.size() == 1 && args[0]->getType()->isArithmeticType()) return to + vec + "(float)(" + a[0] + ")))";
  if (args.size() == (four ? 4u : 2u)) {
    std::string list;
    for (size_t i = 0; i < a.size(); ++i) list += (i ? ", " : "") + std::string("(float)(") + a[i] + ")";
    return to + vec + list + "))";
  }
  return Fail(loc, "this construction of LiteMath::" + t.getUnqualifiedType().getAsString(m_ctx.getPrintingPolicy()) + " is not supported in kernels",
              "build it from a float4 (half4(v)) or from four floats");
}

// A reference: arrays are passed by reference already.
std::string IspcPrinter::WritableParam(QualType type, const std::string& name, SourceLocation loc) {
  const std::string declared = Declare(type, name, loc);
  if (declared.back() == ']') return declared;
  const size_t space = declared.rfind(' ');
  return declared.substr(0, space) + " &" + declared.substr(space + 1);
}

std::unique_ptr<KernelPrinter> IspcPrinter::Sibling(const CXXRecordDecl* cls) const { return std::make_unique<IspcPrinter>(m_ctx, cls, m_reporter); }

}  // namespace crossrt::engine
