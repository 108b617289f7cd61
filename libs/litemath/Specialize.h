// Members whose value the GPU's shaders are compiled for: CRT_SPECIALIZE.
//
//   class Tonemapper {
//     CRT_SPECIALIZE uint32_t m_curve = kCurveAces;  // which curve kernels apply
//     ...
//   };
//
// A kernel of a _Vulkan class reads such a member as a specialization constant, not from the class
// data: the pipelines are made for the value the member holds when CommitDeviceData() runs, so the
// driver folds every branch on it and drops the code the value never reaches. A scene that holds
// triangles only gets a traversal shader without the boxes, fields and motion it does not hold
// (BVHScene::m_sceneKinds); a renderer with one of several tonemapping curves gets that curve's.
//
// The rules:
//   - a data member of type bool, int, uint32_t, float or an enum of 32 bits, of the class or of a
//     composed implementation (public there, as every member a composed traversal reads);
//   - kernels read it and never write it (nor pass it to a non-const reference);
//   - a control function may not change it where a kernel call can follow, in its body or in a
//     member function it calls (the pipelines are made before it records its commands): change it
//     before the call, or after its last kernel call (outside any loop that calls kernels), which
//     the next call then sees. A control function's ...Cmd, recorded into your own command buffer,
//     throws unless CommitDeviceData() has made the pipelines for the values the members hold. A control function
//     finds a changed value and calls CommitDeviceData() itself, which makes the pipelines again, so
//     a value that changes every frame costs a pipeline compilation every frame: mark only what
//     changes with the scene.
//
// _CPU and _ISPC classes, and the class as written, read the member as any other: CRT_SPECIALIZE
// changes what the GPU compiles, never what a kernel computes. Under GCC it expands to nothing.
#pragma once

#if defined(__clang__)
#define CRT_SPECIALIZE [[clang::annotate("crossrt::specialize")]]
#else
#define CRT_SPECIALIZE
#endif
