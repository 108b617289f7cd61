// What the analysis finds in a user class: the input to code generation.
// Everything here is plain text and flags, so generation never touches the Clang AST.
#pragma once
#include <set>
#include <string>
#include <vector>

namespace crossrt::engine {

// Where the user wrote something: the file as Clang opened it, 1-based line and column (an editor
// shows the user's kernels and control functions with what they become: crossrtd --lsp).
struct SourcePlace {
  std::string file;
  unsigned line = 0, column = 0;
};

// A field of a block shared by C++ and GLSL (class data, push constants).
struct BlockField {
  std::string name;
  std::string cppType;   // as the generated C++ mirror declares it
  std::string glslType;  // GLSL type, may end with an array suffix "[N]"
  unsigned std430Align = 4;
  std::string hostExpr;  // how the generated class reaches the value (plain members)
  std::string assignExpr;  // values the generated class computes (device addresses)
};

// TextureArray: std::vector<LiteImage::Texture2D<T>>, an array of combined image samplers (or
// kernel_slicer's ICombinedImageSampler pointers).
enum class MemberKind { Plain, Vector, Image, Sampler, TextureArray };

struct Member {
  std::string name;             // as GLSL and the generated mirrors name it
  std::string hostExpr;         // how the generated class reaches it: the name, or crt_<holder>()->name when composed
  std::string composedFrom;     // composed: "BVHScene::m_nodes through m_pAccelStruct" (for comments)
  MemberKind kind = MemberKind::Plain;
  std::string cppType;          // full C++ type spelling
  std::string glslType;         // plain: the GLSL type; vector: the element's GLSL type; image, texture array: the texel's
  std::string elemCppType;      // vector: the element's C++ type; image, texture array: the texel's
  std::string imageFormat;      // image: GLSL format qualifier (rgba32f, r32f, r32ui)
  std::string vkFormat;         // image: VK_FORMAT_...
  std::string imagePrefix;      // image: "u" for unsigned texels (uimage2D, utexture2D), else ""
  bool scalarLayout = false;    // vector whose element needs GL_EXT_scalar_block_layout to match C++
  bool writtenByKernels = false;
  bool usedByKernels = false;
  bool appendedByKernels = false;  // vector: kernels push_back to it (its size counts on the GPU)
  bool inClassData = false;     // plain: accessible, and its C++ layout matches std430
  unsigned std430Align = 4;     // plain: alignment in a std430 block
  bool padded3 = false;         // plain: an array of LiteMath 3-vectors, held as 4-vectors in the class data (IsArrayOf3Vectors)
  bool specialized = false;     // plain: CRT_SPECIALIZE (Specialize.h), a specialization constant in GLSL
  // texture array: kernel_slicer's ICombinedImageSampler pointers (a vector of them, or one: `singleTexture`),
  // whose texels the generated class gets as float4 textures (LiteImage::TexturesOf)
  bool combinedSamplers = false, singleTexture = false;
};

enum class ReduceOp { Add, Sub, Min, Max };

struct Reduction {
  std::string member;  // the member reduced, or the local (local)
  ReduceOp op = ReduceOp::Add;
  std::string glslType;
  std::string identity;  // GLSL expression of the identity element
  // A local declared before the loop nest (float sum = 0; ... sum += x; ... m = sum / n): its total
  // goes to element 0 of the partials, which <kernel>_Finish adds to the local's initial value.
  bool local = false;
  std::string cppType;  // locals: the C++ type (members: the member's)
};

// A GLSL declaration a shader needs (a struct, a constant, a buffer reference type, a payload),
// with the name it declares: later passes merge and filter declarations by name and never read
// the name back from the text.
struct GlslDecl {
  std::string name;  // the type or constant it declares
  std::string text;
  bool operator==(const GlslDecl& other) const { return name == other.name && text == other.text; }
};

struct KernelParam {
  std::string name;       // as in the user's code
  std::string glslName;   // renamed when it is a GLSL keyword
  std::string cppType;    // by-value parameters: the type as written, for the ...Cmd signature
  std::string valueCppType;  // the value type, for the push-constant mirror
  std::string glslType;
  bool isPointer = false;
  bool isConstPointee = false;
  bool scalarLayout = false;
  bool isThreadId = false;  // RTV kernels: tid, tidX, tidY, tidZ
  // An Image2D reference: an image bound per call (glslType is the texel's), its size in push
  // constants <name>_width and _height. isConstPointee: a const reference.
  bool isImage = false;
  std::string imageFormat, imagePrefix;  // as Member's
  // RTV kernels: a pointer that a control function's thread loop passes a local to (&local). On the
  // GPU it is one value per thread: a function parameter, kept in a buffer between wavefront dispatches.
  bool threadState = false;
  bool narrowed = false;     // a 64-bit integer passed as 32 bits (size_t, int64_t)
  unsigned std430Align = 4;  // by-value parameters: alignment in the push-constant block
};

// An image or sampler a kernel binds: an Image2D member as a storage image (texels loaded and
// stored) or as a texture (sampled), or a LiteImage::Sampler member.
enum class ImageUse { Storage, Texture, Sampler };
struct ImageBinding {
  std::string member;  // or parameter
  ImageUse use = ImageUse::Storage;
  bool loaded = false, stored = false;  // storage images: what the kernel does with the texels
  bool parameter = false;  // an Image2D parameter of the kernel (after the members)
};

struct Loop {                // one parallel dimension of an IPV kernel
  std::string var;
  std::string glslType;      // the loop variable's GLSL type
  std::string startCpp;      // C++ expressions, evaluated on the host when recording
  std::string countCpp;
};

// Virtual functions, level 3, in composed code (paper 3.10, listing 2): a traversal whose leaves
// call a virtual intersection function (ShapeScene::Trace calling m_shapes[i]->Intersect(..., hit)).
// Its kernel gets a ray generation variant, <kernel>_Intersections, in which the ray tracing
// hardware finds the leaves a ray meets (one instance per element, its box from the interface's
// BoxMin() and BoxMax() on the host) and runs the intersection shader of each leaf's class.
// One LeafTraversal per leaf call (vector and method) of the kernel's composed code.
struct LeafTraversal {
  std::string member;         // the VirtualMember: m_scene_m_shapes
  std::string hostExpr;       // crt_m_scene()->m_shapes
  std::string display;        // m_scene->m_shapes
  std::string interfaceName;  // IShape
  std::string method;         // Intersect
  std::string traversal;      // ShapeScene::Trace
  // The paper's form (the call passes a CRT_LeafInfo): the hardware walks each element's leaf boxes,
  // which this host call gives (crt_m_scene()->LeafBoxes(i)); else "": an element is a leaf, its box
  // from the interface's BoxMin() and BoxMax().
  std::string leafBoxes;
  std::vector<std::string> intersectionShaders;  // per class, in the tags' order: hit group firstHitGroup + i is class i
  std::string closestHitShader, missShader;
  unsigned firstHitGroup = 0;  // its traces' SBT record offset
  unsigned missIndex = 0;      // its traces' miss shader, and their payload's location
};

struct Kernel {
  std::string name;
  bool rtv = false;                   // kernel_* called from a loop, else kernel1D/2D/3D_* holding loops
  bool returnsBool = false;           // kernel_* returning bool: its thread loop may leave a loop on it
  unsigned dims = 1;
  std::vector<KernelParam> params;
  std::string cppParamsDecl;          // the parameter list as the user wrote it
  std::string cppArgs;                // its names, as arguments (an _ISPC kernel passes them on to its two ways)
  std::vector<unsigned> threadAxes;   // axis (0=x,1=y,2=z) of each thread-function parameter
  std::vector<Loop> loops;            // IPV: outermost first
  // ISPC: a 2D nest whose iterations call composed code (a traversal) runs foreach_tiled, its lanes
  // a tile of rows and columns: neighbouring rays walk the same nodes (CallsComposedCode in Kernels.cpp).
  bool ispcTiled = false;
  std::vector<Reduction> reductions;
  std::vector<std::string> memberVectors;   // member vectors the kernel reaches (incl. helpers)
  std::vector<ImageBinding> images;         // bound after the buffers, in member declaration order
  std::vector<std::pair<std::string, std::string>> samplePairs;  // (image member, sampler) it samples with
  std::vector<std::pair<std::string, std::string>> paramSamplePairs;  // (image parameter, sampler)
  // Arrays of textures it samples, in member declaration order. Each shader has a variant that
  // samples them with the GPU's samplers (<kernel>_Textures: a descriptor set each, from set 1 on)
  // and one that samples them from buffers as LiteImage does (any device).
  std::vector<std::string> textureArrays;
  // 1D kernel looping to the size of a vector that kernels append to: dispatched indirectly, its
  // thread count read on the GPU.
  std::string indirectVector;
  std::string glslBody;               // the thread's code, as a GLSL function body
  std::string cpuLoopNest;            // IPV, CPU backend: the loop nest with reductions renamed
  std::string cpuLoopHead;            // IPV, CPU backend: crossrt::ParallelFor(...) { before the nest's chunk [crt_first, crt_last)
  std::string cpuPreamble;            // IPV, CPU backend: statements before the loops
  std::vector<std::string> preambleLocals;  // the locals they declare (an ISPC kernel computes its own)
  std::string cpuPostamble;           // IPV, CPU backend: statements after the loops
  // IPV: the statements before and after the loop nest (the paper's loop_start and loop_end), as
  // GLSL functions <kernel>_Start() and <kernel>_Finish() that one thread runs, in shaders of their
  // own dispatched before and after the kernel's threads (and their reductions). Empty when none.
  std::string glslStart, glslFinish;
  std::string sourceFile;             // where the kernel is defined (for comments)
  SourcePlace definedAt;              // its definition's name
  // The GLSL prelude: structs it needs beyond the class's, constants and helper functions, in an
  // order GLSL accepts (composed code is merged in ahead of the kernel's own).
  std::vector<GlslDecl> structList, constantList;
  std::vector<std::string> functionList;
  std::set<std::pair<std::string, std::string>> composedCalls;  // (holder member, interface method)
  // Hardware ray tracing (paper 3.5): when the kernel's only composed calls are ISceneObject's
  // RayQuery_NearestHit / RayQuery_AnyHit through one member, a second shader, <kernel>_RayQuery,
  // answers them with GL_EXT_ray_query against that member's acceleration structure. It leaves out
  // the composed implementation's code and buffers; the host picks it where the device has ray queries.
  std::string rayQueryHolder;
  std::vector<std::string> ownFunctionList;   // functionList before composition merged its code in
  std::vector<std::string> ownMemberVectors;  // memberVectors likewise
  // Megakernel (paper 2.1 and 4.4): the whole body of a thread loop of control function `megakernelOf` in one
  // shader. Its pointer parameters are the buffers its kernels bind (named as those kernels name
  // them), its by-value parameters the control function's variables the body reads.
  std::string megakernelOf;
  std::vector<std::string> megakernelCalls;  // the kernels it runs, whose code it merges
  // The ISPC class: the export function that runs a chunk of the thread loop in SIMD lanes, calling
  // glslBody (then ISPC) per lane (IspcThreadLoops.cpp). Empty where the loop stays C++.
  std::string ispcExport;
  bool bufferReferences = false;      // reaches objects through buffer references (virtual calls)
  bool scalarReferences = false;      // some of them need the scalar layout
  // Virtual functions, level 3: the callable shaders (ClassModel::callables) its virtual calls
  // execute, in executeCallableEXT's numbering, and the prelude of its <kernel>_Callables ray
  // generation shader: the kernel's own structs and functions, the calls' payloads, and dispatchers
  // that execute the object's class's callable shader instead of switching over implementations.
  std::vector<std::string> callables;
  std::vector<GlslDecl> callableStructList;
  std::vector<std::string> callableFunctionList;
  bool atomics = false;               // calls crossrt::Atomic*: coherent buffers, memory scope semantics
  bool floatAtomics = false;          // adds floats atomically (InterlockedAdd, ReduceAdd): GL_EXT_shader_atomic_float
  // Virtual functions, level 3, in composed code: the leaf calls the ray tracing hardware runs, in
  // the traces' numbering (none when the traversal has none; whyNoLeafShaders says why a traversal's
  // leaves stay in software), and the shader code of the variant whose traversal traces a ray where
  // each leaves' loop was.
  std::vector<LeafTraversal> leaves;
  std::string whyNoLeafShaders;
  std::vector<GlslDecl> leafStructList;
  std::vector<std::string> leafFunctionList;
};

struct ControlParam {
  std::string name;
  bool isPointer = false;
  bool isConst = false;
  std::string pointeeCpp;    // element type of a pointer
  std::string sizeExpr;      // from [[crossrt::size("...")]]
  bool hostOnly = false;     // a pointer no kernel gets (memcpy to it after the kernels): no device copy, no size
  // An Image2D (by reference or value): copied to a device image for the call, and back unless
  // const or by value. pointeeCpp is its texel type.
  bool isImage = false;
  std::string vkFormat;
  std::string declText;      // "const float* in", as written minus attributes
};

struct Control {
  std::string name;
  std::string paramsDecl;           // "int n, const float* in"
  std::string argsForward;          // "n, in"
  bool isConst = false;
  bool isVirtual = true;            // else the generated one hides it, and calls through the base run the original
  std::vector<ControlParam> params;
  std::string vulkanCmdBody;        // body with kernel calls turned into ...Cmd calls
  // The statements after its last kernel (or other GPU work) use what kernels write: the Vulkan
  // class's ...Cmd stores them as a lambda that the control function runs after the results are
  // back, not while recording (HostReads.cpp).
  bool hasHostTail = false;
  // Host code between its kernel calls reads members kernels write (a residual, a counter): the
  // Vulkan class's ...Cmd splits its recording there (crt_Synchronize, HostReads.cpp).
  bool synchronizes = false;
  bool swapsVectors = false;        // std::swap of std::vector members (MemberSwaps.cpp)
  std::string cpuBody;              // body with RTV loops parallelised
  std::vector<std::string> kernelsCalled;
  std::vector<std::string> vectorsWritten;  // member vectors its library calls (scan, fill, memcpy), swaps and data() arguments write
  std::vector<std::string> imagesWritten;   // Image2D members it passes to kernels' non-const image parameters
  // A device buffer of the generated class that holds a local of the control function.
  struct LocalBuffer { std::string buffer, cppType, local; };
  // Thread loops calling several kernels: the per-thread locals wavefront mode keeps in buffers.
  std::vector<LocalBuffer> threadStates;
  // std::vector locals it passes to kernels (std::vector<float> temp(n); kernel1D_A(temp.data(), n)),
  // filled as the local's constructor fills it.
  std::vector<LocalBuffer> temporaries;
  std::string sourceFile;
  SourcePlace definedAt;  // its definition's name
};

// kernel_slicer's block-expansion kernel (kernelBE1D_), for the CPU class: its blocks on all cores
// (analyse/BlockKernels.h).
struct BlockKernel {
  std::string name;
  std::string templateHead;  // "template <uint bsize>", or "" for a plain method
  std::string paramsDecl;    // as the definition names them
  std::string body;          // the definition's body, the loop over blocks under an OpenMP pragma
  std::string sourceFile;
};

struct Constructor {
  std::string paramsDecl;  // "int a_w, int a_h"
  std::string paramsWithDefaults;  // "int a_w = 64, int a_h = 48": for declarations
  std::string argsForward; // "a_w, a_h"
};

// Composition (paper 3.6): a member holding an interface whose GPU code and data come from an
// implementation class ("ISceneObject=BVHScene").
struct Composition {
  std::string holder;          // member of the user's class: m_pAccelStruct
  std::string interfaceName;   // ISceneObject
  std::string implName;        // BVHScene
  std::string implHeader;      // file declaring the implementation (included by generated code)
};

// Virtual functions (paper 3.9, level 2): a std::vector member holding pointers to an interface.
// On the GPU each implementation's objects sit in a buffer of their own, and a (class, index) tag
// per element picks the implementation in a switch.
// A data member the generated host code copies but may not name: private or protected in the
// user's class. The host reads it through a member pointer that an explicit instantiation hands
// out (such an instantiation may name any member; see templates' PointerTo).
struct HiddenField {
  std::string tag;        // Lambert_m_albedo: the tag type PointerTo takes, in the generated .cpp
  std::string owner;      // litesdf::SdfSphere: the class that declares it (the impl or a base)
  std::string name;       // m_albedo
  std::string fieldType;  // its C++ type-id, arrays included: float[3]
};

struct VirtualImpl {
  std::string name;                // Lambert
  std::string cppName;             // ns::Lambert: how host C++ names it
  std::string header;              // the file that declares it (generated code includes it)
  std::vector<BlockField> fields;  // its data, base classes' first: the mirror <name>_Data; a hidden
                                   // field's hostExpr reads it through its member pointer
  std::vector<HiddenField> hidden; // the fields host code may not name
  bool scalarLayout = false;       // the mirror matches C++ only with GL_EXT_scalar_block_layout
  unsigned size = 0;               // bytes of the mirror
  unsigned paddingWords = 0;       // level 1: words after the data, so that every class's slot has one size
};

struct VirtualMember {
  std::string member;         // m_materials; composed: m_scene_m_shapes (holder prefix)
  std::string hostExpr;       // how the generated class reaches it: m_materials, crt_m_scene()->m_shapes
  std::string display;        // for messages: m_materials, m_scene->m_shapes
  std::string interfaceName;  // IMaterial
  std::string interfaceCpp;   // ns::IMaterial: how host C++ names it
  std::vector<VirtualImpl> impls;  // every class of the translation unit that implements it
  unsigned slotBytes = 0;          // level 1: the size of every element's slot
  // Its classes' specialization constants are kClassConstantIdBase + firstClassConstant + t, t the
  // class's tag: numbered on after the vectors before it, so that each (vector, class) has its own.
  unsigned firstClassConstant = 0;
};

// Virtual functions, level 3: a shader of a ray tracing pipeline other than the ray generation
// shader. A callable shader (paper 3.9) is one class's implementation of a method called through a
// vector of objects; it receives the call's payload (the objects of the class, the object's index,
// the arguments, room for the result). An intersection shader (paper 3.10) is one class's
// implementation of the intersection function a composed traversal calls per leaf; a closest-hit
// and a miss shader go with them.
struct StageShader {
  std::string name;                   // m_materials_Lambert_Shade: the file (<name>.<stage>) and its SPIR-V
  std::string stage;                  // rcall, rint, rchit or rmiss
  std::string origin;                 // Lambert::Shade
  std::string description;            // what it is, for its header comment
  bool scalarLayout = false;          // the class's objects need GL_EXT_scalar_block_layout
  bool classData = false;             // it reads the class-data block (binding 0): where the objects are
  // Buffers of a composed traversal it reads (an object's method reading them through `this` of the
  // traversal, print/Owner.cpp), bound as kernel `kernel` binds them.
  std::vector<std::string> buffers;
  std::string kernel;
  std::string constants, structs, functions;  // the implementation's code and the payload, in GLSL order
  std::string mainBody;               // loads the object, calls the implementation, stores the result
};

// A member function that appends to a member vector, reached from a kernel's threads: the CPU
// backend hides it with a copy whose push_backs take a lock (crossrt::Locked), as it does in the
// kernels' own loops. Callers on the way from the kernel are copied too, so that they call the copy.
struct LockedCopy {
  std::string name;            // AddHit
  std::string declaration;     // in the class: void AddHit(const Hit& a_hit, int a_n = 1)
  std::string definitionHead;  // void Render_CPU::AddHit(const Hit& a_hit, int a_n)
  std::string sourceFile;      // where the original is defined
  std::string body;            // its body, push_backs rewritten
  bool keepOverloads = false;  // the first copy of a name the class overloads: `using` the others
};

struct ClassModel {
  bool forCpu = false;         // translated for the CPU backend or the ISPC backend (else Vulkan)
  bool forIspc = false;        // translated for the ISPC backend: kernelND_ loop nests as ISPC
  std::string className;       // Render
  std::string namespaceName;   // demo (or a::b) where the class is declared: the generated classes join it
  std::string headerFile;      // header declaring the class (as included by generated code)
  std::vector<Member> members;
  std::vector<Kernel> kernels;
  std::vector<BlockKernel> blockKernels;  // the CPU backend's only
  std::vector<Control> controls;
  std::vector<Constructor> constructors;
  bool usesScanner = false;  // control functions scan on the GPU (std::exclusive_scan / inclusive_scan)
  bool usesSorter = false;   // control functions sort on the GPU (std::sort)
  bool declaresCommitDeviceData = false;
  bool declaresGetExecutionTime = false;
  bool virtualDestructor = false;      // the class's destructor is virtual: the generated ones override it
  std::vector<BlockField> classData;   // plain members + vector sizes, in block order
  std::string templateDir;             // templates/: the shapes of generated code (GLSL the analysis assembles too)
  std::string glslClassStructs;        // structs the class-data block and member vectors need
  std::set<std::string> glslClassStructNames;  // the names they declare
  std::vector<std::string> sourceIncludes;  // #include lines of the sources (quoted ones made absolute)
  std::vector<std::string> usingDecls; // top-level using-directives of the sources: copied bodies need them
  // Declarations of the sources themselves that copied bodies use (static helpers, constants, types;
  // exported functions only declared), in source order, each "// from <file>\n<code>".
  std::vector<std::string> sourceDecls;
  std::vector<Composition> compositions;   // holders kernels call through, in declaration order
  std::vector<VirtualMember> virtuals;     // vectors of objects kernels call virtual functions of
  // 1: one array of equal slots; 2: a buffer per class; 3: as 2, plus callable shaders (the class's
  // own virtual calls) and intersection shaders (composed traversals' leaves) for kernels whose ray
  // generation variant a device with ray tracing pipelines runs.
  int virtualLevel = 2;
  // The generated class (MyRender_Vulkan unless named), and the prefix of the global symbols it
  // defines (MyRender unless named: then the name).
  std::string generatedName, symbolPrefix;
  std::vector<StageShader> callables;      // level 3, by name
  std::vector<StageShader> leafShaders;    // level 3: intersection, closest-hit and miss shaders, by name
  // Thread loops that call several kernels run as one shader each (megakernels) or one dispatch per
  // kernel call (wavefront). Both are generated; this picks the default.
  std::vector<Kernel> megakernels;
  bool megakernelByDefault = false;
  std::vector<LockedCopy> lockedCopies;  // in the order the kernels reach them
};

// The member named `name`, or null (works on a const and a mutable model).
template <typename ModelT>
auto* FindMember(ModelT& model, const std::string& name) {
  for (auto& m : model.members)
    if (m.name == name) return &m;
  return static_cast<decltype(&model.members[0])>(nullptr);
}

}  // namespace crossrt::engine
