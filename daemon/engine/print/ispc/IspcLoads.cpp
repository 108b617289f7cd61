// ISPC loads that do better than a gather.
//
// Whole structs from member vectors. Rays in neighbouring SIMD lanes mostly ask for the
// same element (a BVH node near the root, the one instance of a scene), and a gather of a 128-byte
// node is 32 gathers. So an element of 32 bytes or more, read whole at an index that differs per lane,
// goes through a helper that loads each value the lanes agree on once, for up to four such values,
// and gathers for the lanes left. The helper reads what the gather reads: the result is the same.
// Only a const element qualifies (read in a const method: nothing writes through it), and only one
// read whole, not the base of a field access (m_triangles[g].coord[k] reads 16 of 144 bytes).
//
// Rows of 4-vectors through pointers. A float4, int4 or uint4 read whole through a pointer at a
// per-lane index (a pixel of an image buffer) goes through LiteMath.isph's crt_load4: where all lanes
// read consecutive elements, as a row of pixels does, four vector loads and a transpose instead of
// four gathers (a bloom filter's taps: 1.45x -> 1.75x of _CPU). A statement that stores one whole,
// p[i] = v, goes through crt_store4: a transpose and four vector stores instead of four scatters.
// A struct of eight 32-bit words stored so (a CRT_Hit from a traversal) goes through a helper of its
// own that packs the words for crt_store_words8: eight vector stores instead of eight scatters.
//
// Fields of structs of such rows. A 4-vector field at a 16-byte offset of a struct of two to four
// 16-byte rows (a Box4f's boxMin), read through a pointer or from a member vector at the index of
// a thread loop (boxes[i] in kernel1D_'s loop over i), goes through crt_load4_field: where all lanes
// read consecutive elements, the elements' rows are vector loads and transposes, and each lane picks
// its field's row with shuffles, instead of four gathers at the struct's stride (LBVH::kernel1D_Bounds
// reads boxes[i].boxMin so: its lanes went from 2.9x the scalar loop's time to 0.6x, with AVX2 on an
// AMD EPYC, Zen 5). Any other index keeps the gathers: a loop over spheres inside each thread, where
// every lane reads the same element, ran 20% slower through the helper's tests (SpherePaths_ISPC,
// avx512skx, the same CPU).
//
// And a vector updated through an address with side effects, p[k++] += v: the address found once.
// Part of IspcPrinter (IspcPrinter.h).
#include "analyse/AstQueries.h"
#include "analyse/LoopShape.h"
#include "print/ispc/IspcPrinter.h"
#include "print/ispc/IspcTypes.h"
#include "print/PrinterParts.h"
#include "print/GlslTypes.h"

#include <clang/AST/ParentMapContext.h>

#include <algorithm>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

namespace {

constexpr int64_t kCoherentLoadBytes = 32;  // below this a gather is as cheap as the test
constexpr int kAgreedValues = 4;             // values loaded once before the rest gather

}  // namespace

std::string IspcPrinter::CoherentLoad(const clang::CXXOperatorCallExpr* op) {
  if (op->getOperator() != OO_Subscript || op == m_fieldBase) return "";
  const FieldDecl* field = ThisMemberField(op->getArg(0));
  const QualType element = op->getType().getCanonicalType();
  if (!field || !IsStdVector(field->getType()) || !element.isConstQualified() || !element->isRecordType() ||
      element->isIncompleteType() || m_ctx.getTypeSizeInChars(element).getQuantity() < kCoherentLoadBytes || Uniform(op->getArg(1)))
    return "";
  const auto glsl = GlslTypeOf(element.getUnqualifiedType());
  if (!glsl) return "";
  const std::string type = IspcTypeName(*glsl), helper = "crt_load_" + type;
  if (!std::count(m_coherentLoads.begin(), m_coherentLoads.end(), type)) {
    m_coherentLoads.push_back(type);
    std::ostringstream os;
    os << "// a[i], a " << type << " for each lane: one load for each index the lanes agree on (up to " << kAgreedValues
       << "), a gather for the rest\n"
       << "static inline " << type << " " << helper << "(const uniform " << type << " *uniform a, uint i)\n{\n"
       << "  " << type << " e;\n"
       << "  bool pending = true;\n"
       << "  for (uniform int k = 0; k < " << kAgreedValues << "; ++k)\n  {\n"
       << "    if (!any(pending))\n      return e;\n"
       << "    const uniform uint agreed = extract(i, count_trailing_zeros(lanemask() & packmask(pending)));\n"
       << "    cif (i == agreed)  // coherent: where every lane is on and agrees, e stays in registers (no masked stores)\n"
       << "    {\n      e = a[agreed];\n      pending = false;\n    }\n  }\n"
       << "  if (pending)\n    e = a[i];\n"
       << "  return e;\n}\n";
    m_functions.push_back(os.str());
  }
  return helper + "(" + Expr(op->getArg(0)) + ", ((" + Variability(op->getArg(1)) + "uint)(" + Expr(op->getArg(1)) + ")))";
}

// Whether e's value is only read, as a whole: copied into a new value, or passed to a function by
// value or by const reference (LiteMath's operators take const float4&). Not the target of an
// assignment, a non-const reference, or the object of a non-const method.
bool IspcPrinter::ReadWhole(const clang::Expr* e) {
  const clang::Stmt* child = e;
  while (true) {
    const auto parents = m_ctx.getParents(*child);
    if (parents.size() != 1) return false;
    if (const auto* p = parents[0].get<clang::Expr>();
        p && (isa<ImplicitCastExpr, ParenExpr, MaterializeTemporaryExpr, CXXBindTemporaryExpr, ExprWithCleanups>(p))) {
      if (auto* cast = dyn_cast<ImplicitCastExpr>(p); cast && cast->getCastKind() != CK_NoOp && cast->getCastKind() != CK_LValueToRValue)
        return false;
      child = p;
      continue;
    }
    if (const auto* construct = parents[0].get<CXXConstructExpr>())
      return construct->getConstructor() && construct->getConstructor()->isCopyOrMoveConstructor();
    const auto* call = parents[0].get<CallExpr>();
    const FunctionDecl* callee = call ? call->getDirectCallee() : nullptr;
    if (!callee) return false;
    const auto* method = dyn_cast<CXXMethodDecl>(callee);
    const bool objectFirst = isa<CXXOperatorCallExpr>(call) && method;  // a member operator's arguments start with its object
    if (auto* member = dyn_cast<CXXMemberCallExpr>(call); member && member->getImplicitObjectArgument() &&
                                                          member->getImplicitObjectArgument()->IgnoreParenImpCasts() == child)
      return method && method->isConst();
    for (unsigned k = 0; k < call->getNumArgs(); ++k) {
      if (call->getArg(k) != child) continue;
      if (objectFirst && k == 0) return method->isConst();
      const unsigned param = objectFirst ? k - 1 : k;
      if (param >= callee->getNumParams()) return false;
      const QualType type = callee->getParamDecl(param)->getType();
      return !type->isReferenceType() || type->getPointeeType().isConstQualified();
    }
    return false;
  }
}

std::string IspcPrinter::ConsecutiveLoad(const clang::ArraySubscriptExpr* as, const PointerTarget& t) {
  if (!t.value.empty() || as == m_fieldBase || Uniform(as->getIdx())) return "";
  const QualType element = as->getType();
  if (!IsLiteMathType(element, "float4") && !IsLiteMathType(element, "int4") && !IsLiteMathType(element, "uint4")) return "";
  if (!ReadWhole(as)) return "";
  const std::string i = Expr(as->getIdx());
  return "crt_load4(" + t.array + ", (int)(" + (t.offset.empty() ? i : t.offset + " + " + i) + "))";
}

// Whether e is the variable of the innermost of a kernelND_ function's D thread loops (the loop
// whose iterations neighbouring SIMD lanes run), not of an outer one, of a loop inside a thread, or
// of a loop before the nest (KernelLoopNest decides which loop the nest is, as the analysis does).
static bool IsThreadLoopVariable(ASTContext& ctx, const clang::Expr* e) {
  const auto* ref = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts());
  const auto* var = ref ? dyn_cast<VarDecl>(ref->getDecl()) : nullptr;
  if (!var) return false;
  std::vector<const ForStmt*> loops;  // the for loops around e, from the innermost out to the function
  DynTypedNode node = DynTypedNode::create(*e);
  while (true) {
    const auto parents = ctx.getParents(node);
    if (parents.size() != 1) return false;
    node = parents[0];
    if (const auto* fs = node.get<ForStmt>()) {
      loops.push_back(fs);
    } else if (const auto* fd = node.get<FunctionDecl>()) {
      const std::string name = fd->getNameAsString();
      const size_t dims = name.rfind("kernel1D_", 0) == 0 ? 1 : name.rfind("kernel2D_", 0) == 0 ? 2 : name.rfind("kernel3D_", 0) == 0 ? 3 : 0;
      const auto* body = dyn_cast_or_null<CompoundStmt>(fd->getBody());
      if (dims == 0 || loops.size() < dims || !body || loops.back() != KernelLoopNest(ctx, body)) return false;
      const auto* init = dyn_cast_or_null<DeclStmt>(loops[loops.size() - dims]->getInit());
      return init && init->isSingleDecl() && init->getSingleDecl() == var;
    }
  }
}

std::string IspcPrinter::ConsecutiveFieldLoad(const clang::MemberExpr* me) {
  const auto* field = dyn_cast<FieldDecl>(me->getMemberDecl());
  if (me->isArrow() || !field) return "";
  const QualType type = field->getType();
  const char* vector = IsLiteMathType(type, "float4") ? "float4" : IsLiteMathType(type, "int4") ? "int4" : IsLiteMathType(type, "uint4") ? "uint4" : nullptr;
  if (!vector) return "";
  // The element: a struct of its own fields (no bases) of 2 to 4 rows of 16 bytes, the field one of them.
  const clang::Expr* base = me->getBase()->IgnoreParenImpCasts();
  const auto* record = base->getType()->getAsCXXRecordDecl();
  if (!record || !record->getDefinition() || record->getNumBases() != 0 || field->getParent() != record->getDefinition()) return "";
  const int64_t size = m_ctx.getTypeSizeInChars(base->getType()).getQuantity(), offset = int64_t(m_ctx.getFieldOffset(field) / 8);
  if (size % 16 != 0 || size < 32 || size > 64 || offset % 16 != 0) return "";
  std::string array, index;
  if (auto* as = dyn_cast<ArraySubscriptExpr>(base)) {  // p[i].f through a pointer
    auto* decay = dyn_cast<ImplicitCastExpr>(as->getBase()->IgnoreParens());
    if ((decay && decay->getCastKind() == CK_ArrayToPointerDecay) || !as->getBase()->getType()->isPointerType() || Uniform(as->getIdx()) ||
        !IsThreadLoopVariable(m_ctx, as->getIdx()))
      return "";
    auto t = Pointer(as->getBase());
    if (!t || !t->value.empty() || t->local || t->array.empty()) return "";
    array = t->array;
    index = t->offset.empty() ? Expr(as->getIdx()) : t->offset + " + " + Expr(as->getIdx());
  } else if (auto* sub = dyn_cast<CXXOperatorCallExpr>(base); sub && sub->getOperator() == OO_Subscript) {  // m_v[i].f
    const FieldDecl* member = ThisMemberField(sub->getArg(0));
    if (!member || !IsStdVector(member->getType()) || renames.count(member) || Uniform(sub->getArg(1)) || !IsThreadLoopVariable(m_ctx, sub->getArg(1)))
      return "";
    array = Expr(sub->getArg(0));
    index = Expr(sub->getArg(1)->IgnoreImpCasts());  // i, not its conversion to size_t
  } else {
    return "";
  }
  if (!ReadWhole(me)) return "";
  return "crt_load4_field((const uniform " + std::string(vector) + " *uniform)(" + array + "), (int)(" + index + "), " + std::to_string(size / 16) +
         ", " + std::to_string(offset / 16) + ")";
}

// v[k++] += a for a LiteMath vector element of a buffer, a member vector or a local array: ISPC
// structs have no +=, so it is a[i] = a[i] + v, in a helper that takes the array and the index,
// computed once. A local array is the thread's own (varying elements, each lane its own index).
std::string IspcPrinter::CompoundAssignOnce(const clang::CXXOperatorCallExpr* op) {
  const clang::Expr* target = op->getArg(0)->IgnoreParenImpCasts();
  std::string array, index, pointee = "uniform ", helperKind;
  const VarDecl* localArray = nullptr;
  if (auto* as = dyn_cast<ArraySubscriptExpr>(target))
    if (auto* ref = dyn_cast<DeclRefExpr>(as->getBase()->IgnoreParenImpCasts()))
      if (auto* vd = dyn_cast<VarDecl>(ref->getDecl()); vd && vd->isLocalVarDecl() && vd->getType()->isConstantArrayType()) localArray = vd;
  if (localArray) {
    auto* as = cast<ArraySubscriptExpr>(target);
    array = Expr(as->getBase());
    index = Expr(as->getIdx());
    pointee = "varying ";  // the lanes' own arrays
    helperKind = "_local";
  } else if (auto* as = dyn_cast<ArraySubscriptExpr>(target); as && as->getBase()->getType()->isPointerType()) {
    auto t = Pointer(as->getBase());
    if (!t || !t->value.empty() || t->local || t->array.empty()) return "";
    array = t->array;
    index = t->offset.empty() ? Expr(as->getIdx()) : t->offset + " + " + Expr(as->getIdx());
  } else if (auto* sub = dyn_cast<CXXOperatorCallExpr>(target); sub && sub->getOperator() == OO_Subscript &&
             (IsLiteMathType(sub->getArg(0)->getType(), "float4x4") || IsLiteMathType(sub->getArg(0)->getType(), "float3x3"))) {
    // A column of a thread's local matrix, m[k++] += v: its columns are the lanes' own array.
    auto* ref = dyn_cast<DeclRefExpr>(sub->getArg(0)->IgnoreParenImpCasts());
    auto* vd = ref ? dyn_cast<VarDecl>(ref->getDecl()) : nullptr;
    if (!vd || !vd->isLocalVarDecl()) return "";
    array = "(" + Expr(sub->getArg(0)) + ").m_col";
    index = Expr(sub->getArg(1));
    pointee = "varying ";
    helperKind = "_local";
  } else if (auto* sub = dyn_cast<CXXOperatorCallExpr>(target); sub && sub->getOperator() == OO_Subscript) {
    const FieldDecl* field = ThisMemberField(sub->getArg(0));
    if (!field || !IsStdVector(field->getType())) return "";
    array = Expr(sub->getArg(0));
    index = Expr(sub->getArg(1));
  } else {
    return "";
  }
  const auto glsl = GlslTypeOf(target->getType().getNonReferenceType().getUnqualifiedType());
  if (!glsl) return "";
  const std::string type = IspcTypeName(*glsl), spelling = getOperatorSpelling(op->getOperator());
  const char* names[] = {"add", "sub", "mul", "div"};
  const std::string name = std::string("crt_") + names[std::string("+-*/").find(spelling[0])] + "_assign_" + type + helperKind;
  if (m_helpers.insert(name).second)
    m_functions.push_back("// a[i] " + spelling + " v, a[i] found once" + (helperKind.empty() ? "" : " (a: a thread's local array)") + "\nstatic inline " + type +
                          " " + name + "(" + pointee + type + " *uniform a, int i, " + type + " v)\n{\n  a[i] = a[i] " + spelling.substr(0, 1) +
                          " v;\n  return a[i];\n}\n");
  return name + "(" + array + ", (int)(" + index + "), " + Expr(op->getArg(1)) + ")";
}

// The words of a struct of eight 32-bit fields (floats, ints and arrays of them, no bases), as ISPC
// expressions of a value `v` spelled as floats; empty for any other struct.
static std::vector<std::string> EightWords(ASTContext& ctx, QualType type) {
  const auto* record = type->getAsCXXRecordDecl();
  if (!record || !record->getDefinition() || record->getNumBases() != 0 || ctx.getTypeSize(type) != 8 * 32) return {};
  std::vector<std::string> words;
  auto word = [&](QualType t, const std::string& access) {
    t = t.getCanonicalType();
    if (t->isSpecificBuiltinType(BuiltinType::Float)) words.push_back(access);
    else if (t->isIntegerType() && ctx.getTypeSize(t) == 32) words.push_back("floatbits((unsigned int32)" + access + ")");
    else return false;
    return true;
  };
  for (const FieldDecl* f : record->fields()) {
    const std::string access = "v." + f->getNameAsString();
    if (const auto* array = ctx.getAsConstantArrayType(f->getType())) {
      for (uint64_t k = 0; k < array->getSize().getZExtValue(); ++k)
        if (!word(array->getElementType(), access + "[" + std::to_string(k) + "]")) return {};
    } else if (!word(f->getType(), access)) {
      return {};
    }
  }
  return words.size() == 8 ? words : std::vector<std::string>{};
}

std::string IspcPrinter::ConsecutiveStore(const clang::CXXOperatorCallExpr* op) {
  if (op->getOperator() != OO_Equal || op->getNumArgs() != 2) return "";
  const auto* as = dyn_cast<ArraySubscriptExpr>(op->getArg(0)->IgnoreParenImpCasts());
  if (!as || !as->getBase()->getType()->isPointerType() || Uniform(as->getIdx())) return "";
  // A member array whose elements the kernel reduces is each lane's own array (crt_m_lowLocal), not memory.
  if (auto* me = dyn_cast<MemberExpr>(as->getBase()->IgnoreParenImpCasts()); me && renames.count(me->getMemberDecl())) return "";
  const QualType element = as->getType().getUnqualifiedType();
  // A struct of eight words (a CRT_Hit) goes through a helper of its own: crt_store_words8 after
  // packing its fields, or the scatters.
  std::string store = "crt_store4";
  if (IsLiteMathType(element)) {
    if (!IsLiteMathType(element, "float4") && !IsLiteMathType(element, "int4") && !IsLiteMathType(element, "uint4")) return "";
  } else if (const auto words = EightWords(m_ctx, element); !words.empty()) {
    const auto glsl = GlslTypeOf(element);
    if (!glsl) return "";
    const std::string type = IspcTypeName(*glsl);
    store = "crt_store_" + type;
    if (m_helpers.insert(store).second) {
      std::string packed;
      for (const auto& w : words) packed += ", " + w;
      m_functions.push_back("// a[i] = v for each lane, " + type + " being eight 32-bit words: vector stores where the lanes write\n"
                            "// consecutive elements (crt_store_words8 in LiteMath.isph), otherwise the scatters\n"
                            "static inline void " + store + "(uniform " + type + " *uniform a, int i, " + type + " v)\n{\n"
                            "  if (!crt_consecutive(i))\n    a[i] = v;\n  else\n    crt_store_words8((uniform float *uniform)(a + extract(i, 0))" +
                            packed + ");\n}\n");
    }
  } else {
    return "";
  }
  const clang::Stmt* statement = op;  // a statement of its own (its value is not used), with any temporaries' cleanups
  auto parents = m_ctx.getParents(*statement);
  while (parents.size() == 1 && parents[0].get<ExprWithCleanups>()) {
    statement = parents[0].get<ExprWithCleanups>();
    parents = m_ctx.getParents(*statement);
  }
  if (parents.size() != 1 || parents[0].get<clang::Expr>() || !parents[0].get<clang::Stmt>()) return "";
  auto t = Pointer(as->getBase());
  if (!t || !t->value.empty() || t->local || t->array.empty()) return "";
  const std::string i = Expr(as->getIdx());
  return store + "(" + t->array + ", (int)(" + (t->offset.empty() ? i : t->offset + " + " + i) + "), " + Expr(op->getArg(1)) + ")";
}

}  // namespace crossrt::engine
