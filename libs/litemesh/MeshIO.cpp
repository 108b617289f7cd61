#include "MeshIO.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <zlib.h>

#include <filesystem>
#include <stdexcept>

namespace {

// The whole decompressed contents of a gzip file.
std::vector<char> Gunzip(const std::string& path)
{
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file)
    throw std::runtime_error(path + ": cannot open");
  std::vector<char> data;
  char chunk[1 << 16];
  int got = 0;
  while ((got = gzread(file, chunk, sizeof(chunk))) > 0)
    data.insert(data.end(), chunk, chunk + got);
  int error = Z_OK;
  const std::string message = got < 0 ? gzerror(file, &error) : "";
  gzclose(file);
  if (got < 0)
    throw std::runtime_error(path + ": not a readable gzip file (" + message + ")");
  return data;
}

}  // namespace

TriangleMesh LoadMesh(const std::string& path)
{
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error(path + ": no such file");
  const unsigned flags = aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType;
  Assimp::Importer importer;
  const aiScene* scene = nullptr;
  const std::filesystem::path p(path);
  if (p.extension() == ".gz")
  {
    const std::vector<char> data = Gunzip(path);
    const std::string hint = p.stem().extension().string();  // "dragon.ply.gz" -> ".ply"
    scene = importer.ReadFileFromMemory(data.data(), data.size(), flags, hint.empty() ? "" : hint.c_str() + 1);
  }
  else
    scene = importer.ReadFile(path, flags);
  if (!scene || !scene->mRootNode)
    throw std::runtime_error(path + ": not a mesh file the importer reads (" + importer.GetErrorString() + ")");

  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
  {
    const aiMesh* in = scene->mMeshes[m];
    if (!(in->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
      continue;  // points and lines
    const uint32_t base = uint32_t(mesh.VertexCount());
    for (unsigned v = 0; v < in->mNumVertices; ++v)
      mesh.positions.insert(mesh.positions.end(), {in->mVertices[v].x, in->mVertices[v].y, in->mVertices[v].z});
    for (unsigned f = 0; f < in->mNumFaces; ++f)
      if (in->mFaces[f].mNumIndices == 3)
        for (unsigned k = 0; k < 3; ++k)
          mesh.indices.push_back(base + in->mFaces[f].mIndices[k]);
  }
  if (mesh.indices.empty())
    throw std::runtime_error(path + ": the file holds no triangles");
  return mesh;
}
