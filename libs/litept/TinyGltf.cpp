// tinygltf's implementation, compiled into litept rather than taken from Debian's libtinygltf.so:
// other shared libraries (libdraco, through assimp) export tinygltf symbols built without file
// access, and a program linking both could bind to those. Images are decoded by OpenImageIO
// (DecodeGltfImage, SceneLoader.cpp), not stb_image, which Debian packages as a library of its own.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#include <tiny_gltf.h>
