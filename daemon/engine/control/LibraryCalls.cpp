// Library calls in control functions on data the GPU holds: std::sort and std::stable_sort,
// std::exclusive_scan and std::inclusive_scan, std::reduce, memcpy, std::copy and std::fill. Each
// becomes a call of the runtime's primitive on device buffers.

#include "generate/GeneratedNames.h"
#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "control/ControlFunctions.h"
#include "control/ControlRewriter.h"
#include "analyse/LoopShape.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

std::optional<ControlRewriter::Position> ControlRewriter::PositionOf(const Expr* e) {
  e = e->IgnoreParenImpCasts();
  if (auto* bo = dyn_cast<BinaryOperator>(e); bo && bo->getOpcode() == BO_Add) {
    auto p = PositionOf(bo->getLHS());
    if (!p || p->isEnd) return std::nullopt;
    p->offset = (p->offset.empty() ? "" : p->offset + " + ") + AsOperand(m_c.Text(bo->getRHS()->getSourceRange()));
    return p;
  }
  if (auto* op = dyn_cast<CXXOperatorCallExpr>(e); op && op->getOperator() == OO_Plus && op->getNumArgs() == 2) {
    auto p = PositionOf(op->getArg(0));
    if (!p || p->isEnd) return std::nullopt;
    p->offset = (p->offset.empty() ? "" : p->offset + " + ") + AsOperand(m_c.Text(op->getArg(1)->getSourceRange()));
    return p;
  }
  if (auto* dr = dyn_cast<DeclRefExpr>(e))
    if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl()); p && p->getDeclContext() == m_def && p->getType()->isPointerType())
      return Position{generated::kInOutPrefix + m_ctrl.name + "." + p->getNameAsString(), p->getNameAsString(), "", p->getType()->getPointeeType().getUnqualifiedType()};
  if (auto* mc = dyn_cast<CXXMemberCallExpr>(e)) {
    std::string method = mc->getMethodDecl() ? mc->getMethodDecl()->getNameAsString() : "";
    auto* f = ThisField(mc->getImplicitObjectArgument());
    QualType element;
    if (f && IsStdVector(f->getType(), &element) && (method == "begin" || method == "end" || method == "data")) {
      Member* m = FindMember(m_c.model, f->getNameAsString());
      if (!m) return std::nullopt;
      m->usedByKernels = true;  // so that it gets a device buffer
      Position p{generated::kVectorCopies + "." + m->name + ".View()", m->name, "", element.getUnqualifiedType(), m};
      p.isEnd = method == "end";
      return p;
    }
  }
  return std::nullopt;
}

std::string ControlRewriter::ViewAt(const Position& p) {
  if (p.offset.empty()) return p.view;
  return "crossrt::Offset(" + p.view + ", sizeof(" + CppTypeName(m_c.ctx, p.element) + ") * size_t(" + p.offset + "))";
}

std::optional<std::string> ControlRewriter::Count(const Position& first, const Position& last) {
  if (first.key != last.key) return std::nullopt;
  std::string end = last.isEnd ? first.vector->name + ".size()" : last.offset;
  if (end.empty()) end = "0";
  // In parentheses as a whole: callers put a type in front (uint32_t(n)).
  return first.offset.empty() ? "(" + end + ")" : "(" + AsOperand(end) + " - " + AsOperand(first.offset) + ")";
}

void ControlRewriter::WrittenVector(const Position& p) {
  if (p.vector && std::find(m_ctrl.vectorsWritten.begin(), m_ctrl.vectorsWritten.end(), p.vector->name) == m_ctrl.vectorsWritten.end())
    m_ctrl.vectorsWritten.push_back(p.vector->name);
}

std::string ControlRewriter::ElementTypeName(QualType t) {
  const auto* bt = t.getCanonicalType()->getAs<BuiltinType>();
  if (!bt) return "";
  return bt->getKind() == BuiltinType::UInt ? "Uint" : bt->getKind() == BuiltinType::Int ? "Int" : bt->getKind() == BuiltinType::Float ? "Float" : "";
}

std::optional<std::pair<const ParmVarDecl*, uint64_t>> ControlRewriter::KeyPath(const Expr* e, std::string& keyType) {
  e = e->IgnoreParenImpCasts();
  uint64_t offset = 0;
  const Expr* base = e;
  keyType = ElementTypeName(e->getType());
  while (auto* me = dyn_cast<MemberExpr>(base)) {
    auto* fd = dyn_cast<FieldDecl>(me->getMemberDecl());
    if (!fd || me->isArrow() || fd->isBitField()) return std::nullopt;
    offset += m_c.ctx.getFieldOffset(fd) / 8;
    base = me->getBase()->IgnoreParenImpCasts();
  }
  auto* dr = dyn_cast<DeclRefExpr>(base);
  auto* parm = dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
  if (!parm) return std::nullopt;
  return std::make_pair(parm, offset);
}

std::optional<ControlRewriter::SortOrder> ControlRewriter::OrderOf(const CallExpr* call, QualType element, std::string& why) {
  const std::string scalarType = ElementTypeName(element);
  if (call->getNumArgs() == 2) {
    if (scalarType.empty()) why = "sorting elements without a comparator needs uint32_t, int or float elements";
    return scalarType.empty() ? std::nullopt : std::optional<SortOrder>(SortOrder{0, scalarType, false});
  }
  const Expr* cmp = call->getArg(2)->IgnoreImplicit()->IgnoreParenImpCasts();
  if (auto* mt = dyn_cast<MaterializeTemporaryExpr>(cmp)) cmp = mt->getSubExpr()->IgnoreImplicit();
  if (auto* record = cmp->getType()->getAsCXXRecordDecl(); record && record->isInStdNamespace() &&
                                                        (record->getName() == "less" || record->getName() == "greater")) {
    if (scalarType.empty()) why = "std::less and std::greater sort uint32_t, int or float elements on the GPU";
    return scalarType.empty() ? std::nullopt : std::optional<SortOrder>(SortOrder{0, scalarType, record->getName() == "greater"});
  }
  why = "the GPU sort understands comparators of the form `[](T a, T b) { return a.key < b.key; }` (or `>`) with a "
        "uint32_t, int or float key";
  auto* lambda = dyn_cast<LambdaExpr>(cmp);
  if (!lambda) return std::nullopt;
  auto* op = lambda->getCallOperator();
  auto* body = dyn_cast_or_null<CompoundStmt>(op->getBody());
  if (!body || body->size() != 1 || op->getNumParams() != 2) return std::nullopt;
  auto* ret = dyn_cast<ReturnStmt>(body->body_front());
  auto* cmpOp = ret && ret->getRetValue() ? dyn_cast<BinaryOperator>(ret->getRetValue()->IgnoreParenImpCasts()) : nullptr;
  if (!cmpOp || (cmpOp->getOpcode() != BO_LT && cmpOp->getOpcode() != BO_GT)) return std::nullopt;
  std::string lType, rType;
  auto l = KeyPath(cmpOp->getLHS(), lType), r = KeyPath(cmpOp->getRHS(), rType);
  if (!l || !r || l->second != r->second || l->first == r->first) return std::nullopt;
  if (lType.empty() || lType != rType) return std::nullopt;
  // Both parameters must be the element type (by value or const reference).
  for (auto* parm : op->parameters())
    if (!m_c.ctx.hasSameUnqualifiedType(parm->getType().getNonReferenceType(), element)) return std::nullopt;
  const uint64_t size = m_c.ctx.getTypeSizeInChars(element).getQuantity();
  if (size % 4 != 0 || l->second % 4 != 0) {
    why = "the GPU sort moves whole 32-bit words: the element's size and the key's offset must be multiples of 4 bytes";
    return std::nullopt;
  }
  const bool firstOnLeft = l->first == op->getParamDecl(0);
  const bool descending = (cmpOp->getOpcode() == BO_GT) == firstOnLeft;
  return SortOrder{uint32_t(l->second / 4), lType, descending};
}

bool ControlRewriter::ReduceAddInit(const CallExpr* call) {
  auto* f = call->getNumArgs() == 2 ? ThisField(call->getArg(0)) : nullptr;
  Member* m = f ? FindMember(m_c.model, f->getNameAsString()) : nullptr;
  if (!m || m->kind != MemberKind::Vector) {
    m_c.rep.RecordingError(call->getBeginLoc(), "ReduceAddInit of something other than a std::vector member", "pass the member vector kernels add into");
    return true;
  }
  SourceLocation end = Lexer::findLocationAfterToken(call->getEndLoc(), tok::semi, m_c.ctx.getSourceManager(), m_c.ctx.getLangOpts(), false);
  if (end.isInvalid()) {
    m_c.rep.RecordingError(call->getBeginLoc(), "ReduceAddInit used inside an expression in control function '" + m_ctrl.name + "'",
                           "call it as a statement of its own: ReduceAddInit(" + m->name + ", n);");
    return true;
  }
  m->usedByKernels = true;
  WrittenVector({"", m->name, "", {}, m});
  m_gpu.InsertTextAfter(end, "\ncrossrt::ZeroCmd(crt_cmd, crt_vdata." + m->name + ", sizeof(" + m->elemCppType + ") * " + m->name + ".size(), \"" +
                             m_c.cls->getNameAsString() + "::" + m->name + "\");  // its device copy starts at zero too\n");
  return true;
}

bool ControlRewriter::IsAddition(const Expr* op) {
  op = op->IgnoreImplicit()->IgnoreParenImpCasts();
  if (auto* mt = dyn_cast<MaterializeTemporaryExpr>(op)) op = mt->getSubExpr()->IgnoreImplicit();
  if (auto* rd = op->getType()->getAsCXXRecordDecl(); rd && rd->isInStdNamespace() && rd->getName() == "plus") return true;
  auto* lambda = dyn_cast<LambdaExpr>(op);
  if (!lambda || lambda->getCallOperator()->getNumParams() != 2) return false;
  auto* body = dyn_cast_or_null<CompoundStmt>(lambda->getCallOperator()->getBody());
  auto* ret = body && body->size() == 1 ? dyn_cast<ReturnStmt>(body->body_front()) : nullptr;
  auto* sum = ret && ret->getRetValue() ? dyn_cast<BinaryOperator>(ret->getRetValue()->IgnoreParenImpCasts()) : nullptr;
  if (!sum || sum->getOpcode() != BO_Add) return false;
  auto param = [](const Expr* e) {
    auto* dr = dyn_cast<DeclRefExpr>(e->IgnoreParenImpCasts());
    return dr ? dyn_cast<ParmVarDecl>(dr->getDecl()) : nullptr;
  };
  const ParmVarDecl *a = param(sum->getLHS()), *b = param(sum->getRHS());
  return a && b && a != b;
}

bool ControlRewriter::MentionsHostOnlyPointer(const Expr* e) const {
  struct Refs : RecursiveASTVisitor<Refs> {
    const CXXRecordDecl* cls; bool found = false;
    bool VisitDeclRefExpr(DeclRefExpr* dr) {
      if (auto* p = dyn_cast<ParmVarDecl>(dr->getDecl())) found |= IsHostOnlyPointer(p, cls);
      return true;
    }
  } refs;
  refs.cls = m_c.cls;
  refs.TraverseStmt(const_cast<Expr*>(e));
  return refs.found;
}

bool ControlRewriter::TryLibraryCall(const CallExpr* call) {
  auto* fd = call->getDirectCallee();
  if (!fd) return false;
  // Host memory no kernel sees (memcpy(out, m_v.data(), ...) to a pointer only host code uses):
  // the call runs on the host, as written, after what the kernels wrote is read back.
  if (MentionsHostOnlyPointer(call)) return false;
  std::string name = fd->getNameAsString();
  if (name == "ReduceAddInit" && InLiteMath(fd)) return ReduceAddInit(call);
  bool inStd = fd->isInStdNamespace() || IsSystemDecl(fd);
  if (!inStd) return false;
  auto bad = [&](const std::string& why) {
    m_c.rep.RecordingError(call->getBeginLoc(), "'" + fd->getQualifiedNameAsString() + "' on device data: " + why,
                        "use member std::vector begin()/end()/data() or size-annotated pointer parameters, with + offsets");
    return true;
  };
  std::string replacement;
  const unsigned nargs = call->getNumArgs();
  if ((name == "exclusive_scan" && (nargs == 4 || nargs == 5)) || (name == "inclusive_scan" && nargs >= 3 && nargs <= 5)) {
    // exclusive_scan(first, last, out, init[, op]); inclusive_scan(first, last, out[, op[, init]]).
    const Expr* op = name == "exclusive_scan" ? (nargs == 5 ? call->getArg(4) : nullptr) : (nargs >= 4 ? call->getArg(3) : nullptr);
    const Expr* initArg = name == "exclusive_scan" ? call->getArg(3) : (nargs == 5 ? call->getArg(4) : nullptr);
    if (op && !IsAddition(op)) return bad("scans on the GPU add: the operation must be std::plus or a lambda returning a + b");
    auto first = PositionOf(call->getArg(0)), last = PositionOf(call->getArg(1)), out = PositionOf(call->getArg(2));
    if (!first || !last || !out) return bad("its ranges are not device buffers the translator can name");
    auto count = Count(*first, *last);
    if (!count) return bad("first and last must belong to the same buffer");
    const std::string type = ElementTypeName(first->element);
    if (type.empty()) return bad("scans on the GPU take uint32_t, int or float elements");
    std::string elem = CppTypeName(m_c.ctx, first->element);
    std::string init = initArg ? "crossrt::Bits32(static_cast<" + elem + ">(" + m_c.Text(initArg->getSourceRange()) + "))" : "0u";
    m_c.model.usesScanner = true;
    replacement = generated::kScanner + ".RecordCmd(crt_cmd, " + ViewAt(*first) + ", " + ViewAt(*out) + ", uint32_t" + *count + ", " +
                  (name == "inclusive_scan" ? "true" : "false") + ", crossrt::ElementType::" + type + ", " + init + ")";
    WrittenVector(*out);
  } else if (name == "sort" && (call->getNumArgs() == 2 || call->getNumArgs() == 3)) {
    auto first = PositionOf(call->getArg(0)), last = PositionOf(call->getArg(1));
    if (!first || !last) return bad("its range is not a device buffer the translator can name");
    auto count = Count(*first, *last);
    if (!count) return bad("first and last must belong to the same buffer");
    std::string why;
    auto order = OrderOf(call, first->element, why);
    if (!order) return bad(why);
    const uint64_t words = m_c.ctx.getTypeSizeInChars(first->element).getQuantity() / 4;
    const std::string key = "crossrt::SortKey{" + std::to_string(words) + ", " + std::to_string(order->keyWord) +
                            ", crossrt::ElementType::" + order->type + ", " + (order->descending ? "true" : "false") + "}";
    m_c.model.usesSorter = true;
    replacement = generated::kSorter + ".RecordCmd(crt_cmd, " + ViewAt(*first) + ", uint32_t" + *count + ", " + key + ")";
    // A vector that kernels append to has its size on the GPU: the sort reads it there.
    if (first->vector && m_c.appended.count(first->vector->name)) {
      if (!IsWholeVector(call)) return bad("'" + first->vector->name + "' is appended to by kernels, so its size is known only on the GPU: sort all of it, from begin() to end()");
      const std::string v = first->vector->name;
      m_c.model.usesSorter = true;
      replacement = generated::kSorter + ".RecordCmd(crt_cmd, " + first->view + ", uint32_t(" + generated::kVectorCopies + "." + v + "Capacity), " + key +
                    ", crt_classDataBuffer.View(), offsetof(ClassData, " + generated::SizeField(v) + "))";
    }
    // The CPU backend sorts on all cores too, with the same radix sort.
    m_cpu.ReplaceText(call->getSourceRange(), "crossrt::RadixSort(" + m_c.Text(call->getArg(0)->getSourceRange()) + ", " +
                                                  m_c.Text(call->getArg(1)->getSourceRange()) + ", " + key + ")");
    WrittenVector(*first);
  } else if ((name == "memcpy" || name == "memmove") && call->getNumArgs() == 3) {
    auto dst = PositionOf(call->getArg(0)), src = PositionOf(call->getArg(1));
    if (!dst || !src || dst->isEnd || src->isEnd) return bad("source and destination must be device buffers");
    replacement = "crossrt::CopyCmd(crt_cmd, " + ViewAt(*src) + ", " + ViewAt(*dst) + ", VkDeviceSize(" + m_c.Text(call->getArg(2)->getSourceRange()) + "))";
    WrittenVector(*dst);
  } else if (name == "fill" && call->getNumArgs() == 3) {
    auto first = PositionOf(call->getArg(0)), last = PositionOf(call->getArg(1));
    if (!first || !last) return bad("its range is not a device buffer the translator can name");
    auto count = Count(*first, *last);
    if (!count) return bad("first and last must belong to the same buffer");
    if (m_c.ctx.getTypeSizeInChars(first->element).getQuantity() != 4) return bad("GPU fills take 32-bit elements");
    std::string elem = CppTypeName(m_c.ctx, first->element);
    replacement = "crossrt::FillCmd(crt_cmd, " + ViewAt(*first) + ", sizeof(" + elem + ") * VkDeviceSize" + *count +
                  ", crossrt::Bits32(static_cast<" + elem + ">(" + m_c.Text(call->getArg(2)->getSourceRange()) + ")))";
    WrittenVector(*first);
  } else {
    // Any other library call handed pointers or iterators into device data would run on the
    // host copy while the GPU holds the data: silently wrong, so refuse it.
    for (auto* arg : call->arguments()) {
      QualType t = arg->getType();
      bool pointerLike = t->isPointerType() || (t->getAsCXXRecordDecl() && t->getAsCXXRecordDecl()->getName().contains("iterator"));
      if (pointerLike && PositionOf(arg))
        return bad("on device data the GPU runs std::sort, std::exclusive_scan and std::inclusive_scan (adding), std::fill, memcpy and "
                   "LiteMath's ReduceAddInit; this call would run on a stale host copy");
    }
    return false;
  }
  m_gpu.ReplaceText(call->getSourceRange(), replacement);
  return true;
}

}  // namespace crossrt::engine
