#include "scene/ply_mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>

#include "scene/scene_desc.h"

namespace tessera {

PlyMesh load_ply_mesh(const std::string& path) {
  Assimp::Importer importer;
  // Triangulate only: anything that merges or reorders vertices would change
  // what the file says (and shading normals with it).
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate);
  if (!scene) throw SceneError("cannot read PLY '" + path + "': " + importer.GetErrorString());
  PlyMesh out;
  bool all_have_normals = true, all_have_uv = true;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    all_have_normals &= scene->mMeshes[m]->HasNormals();
    all_have_uv &= scene->mMeshes[m]->HasTextureCoords(0);
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const uint32_t base = static_cast<uint32_t>(out.p.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      out.p.emplace_back(p.x, p.y, p.z);
      if (all_have_normals) out.n.emplace_back(mesh->mNormals[v].x, mesh->mNormals[v].y, mesh->mNormals[v].z);
      if (all_have_uv) out.uv.emplace_back(mesh->mTextureCoords[0][v].x, mesh->mTextureCoords[0][v].y);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines left over after triangulation
      for (int k = 0; k < 3; ++k) out.indices.push_back(base + face.mIndices[k]);
    }
  }
  if (out.indices.empty()) throw SceneError("cannot read PLY '" + path + "': no triangles");
  return out;
}

}  // namespace tessera
