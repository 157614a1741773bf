// Mesh goal importer: Assimp reads the file, top_view.h renders it.
#include "shapes/mesh_importer.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/IOStream.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <system_error>
#include <tuple>
#include <utility>

#include "shapes/sidecar.h"

namespace hj {
namespace {

// Rotation taking the model's up direction to +z, as a map of one vertex.
// Each case is a proper rotation (determinant +1), so handedness is kept.
Eigen::Vector3d to_z_up(const aiVector3D& v, char axis, bool negative) {
  const double x = v.x, y = v.y, z = v.z;
  switch (axis) {
    case 'x': return negative ? Eigen::Vector3d(y, -z, -x) : Eigen::Vector3d(y, z, x);
    case 'y': return negative ? Eigen::Vector3d(x, z, -y) : Eigen::Vector3d(x, -z, y);
    default: return negative ? Eigen::Vector3d(x, -y, -z) : Eigen::Vector3d(x, y, z);
  }
}

long count_triangles(const aiScene& scene) {
  long n = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    for (unsigned f = 0; f < scene.mMeshes[m]->mNumFaces; ++f) n += scene.mMeshes[m]->mFaces[f].mNumIndices == 3;
  return n;
}

// The triangles the file will become once its polygons are triangulated and
// every instance of a mesh is copied into place, counted on the raw scene
// (before post-processing allocates them). Saturates above `limit`.
long triangles_after_processing(const aiScene& scene, long limit) {
  std::vector<long> per_mesh(scene.mNumMeshes, 0);
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    for (unsigned f = 0; f < scene.mMeshes[m]->mNumFaces; ++f)
      per_mesh[m] += std::max(0L, long(scene.mMeshes[m]->mFaces[f].mNumIndices) - 2);
  long total = 0;
  std::vector<const aiNode*> nodes = {scene.mRootNode};
  while (!nodes.empty() && total <= limit) {
    const aiNode* node = nodes.back();
    nodes.pop_back();
    if (node == nullptr) continue;
    for (unsigned i = 0; i < node->mNumMeshes; ++i)
      if (node->mMeshes[i] < scene.mNumMeshes) total += per_mesh[node->mMeshes[i]];
    for (unsigned c = 0; c < node->mNumChildren; ++c) nodes.push_back(node->mChildren[c]);
  }
  return total;
}

// A stream that tells `open` when it is deleted, however Assimp deletes it
// (through Close, or directly).
class TrackedStream final : public Assimp::IOStream {
 public:
  TrackedStream(Assimp::IOStream* file, std::set<Assimp::IOStream*>& open) : file_(file), open_(open) {}
  ~TrackedStream() override {
    open_.erase(this);
    delete file_;
  }
  size_t Read(void* buffer, size_t size, size_t count) override { return file_->Read(buffer, size, count); }
  size_t Write(const void* buffer, size_t size, size_t count) override { return file_->Write(buffer, size, count); }
  aiReturn Seek(size_t offset, aiOrigin origin) override { return file_->Seek(offset, origin); }
  size_t Tell() const override { return file_->Tell(); }
  size_t FileSize() const override { return file_->FileSize(); }
  void Flush() override { file_->Flush(); }

 private:
  Assimp::IOStream* file_;
  std::set<Assimp::IOStream*>& open_;
};

// Assimp's file access, confined to the folder of the mesh being imported:
// a file the mesh names (a glTF buffer or image, an OBJ material library) is
// read only from inside that folder, never through "..", an absolute path
// elsewhere or a URI. The server gives each upload a folder of its own.
class ConfinedIOSystem final : public Assimp::DefaultIOSystem {
 public:
  explicit ConfinedIOSystem(const std::filesystem::path& file)
      : folder_(std::filesystem::weakly_canonical(std::filesystem::absolute(file).parent_path())) {}
  // Assimp 5.2's glTF reader does not close a buffer it fails to read (a
  // file descriptor per malformed upload): what it left open is closed here.
  ~ConfinedIOSystem() override {
    const std::set<Assimp::IOStream*> left = open_;
    for (Assimp::IOStream* stream : left) delete stream;
  }

  bool Exists(const char* path) const override {
    if (!inside(path)) return refuse(path);
    return DefaultIOSystem::Exists(path);
  }
  Assimp::IOStream* Open(const char* path, const char* mode) override {
    if (!inside(path) || std::string(mode).find_first_of("wa+") != std::string::npos) return refuse(path), nullptr;
    Assimp::IOStream* file = DefaultIOSystem::Open(path, mode);
    if (!file) return nullptr;
    Assimp::IOStream* stream = new TrackedStream(file, open_);
    open_.insert(stream);
    return stream;
  }
  // The first path refused, "" if none.
  const std::string& refused() const { return refused_; }

 private:
  bool refuse(const char* path) const {
    if (refused_.empty()) refused_ = path;
    return false;
  }
  bool inside(const std::string& path) const {
    // A URI, or an absolute path the importer appended to the mesh's folder.
    if (path.find("//") != std::string::npos) return false;
    std::error_code error;
    const std::filesystem::path target = std::filesystem::weakly_canonical(std::filesystem::absolute(path), error);
    if (error) return false;
    const auto [end, rest] = std::mismatch(folder_.begin(), folder_.end(), target.begin(), target.end());
    return end == folder_.end() && rest != target.end();
  }

  std::filesystem::path folder_;
  mutable std::string refused_;
  std::set<Assimp::IOStream*> open_;
};

class MeshImporter final : public GoalImporter {
 public:
  std::string name() const override { return "mesh"; }
  std::vector<std::string> extensions() const override { return {".3mf", ".glb", ".gltf", ".obj", ".ply", ".stl"}; }

  HeightMap import(const std::filesystem::path& file, const ImportOptions& options) const override {
    // Memory guard: the grid is at most mesh_resolution pixels square.
    if (double(options.mesh_resolution) * options.mesh_resolution > double(options.max_pixels))
      throw ImportError(file, "a " + std::to_string(options.mesh_resolution) + " pixel square top view (ImportOptions." +
                                  "mesh_resolution) is over the limit of " + std::to_string(options.max_pixels) +
                                  " pixels (ImportOptions.max_pixels)");
    const std::vector<Triangle3d> triangles = load_mesh_triangles(file, options);
    TopView view;
    try {
      view = render_top_view(triangles, options.mesh_resolution);
    } catch (const std::invalid_argument& e) {
      throw ImportError(file, std::string("seen from its up axis (ImportOptions.mesh_up_axis), ") + e.what());
    }
    if (view.z.array().isNaN().all())
      throw ImportError(file, "no surface is seen from above (every triangle is edge-on to ImportOptions.mesh_up_axis)");
    // Lowest visible surface = 0; NaN (uncovered) is skipped by the min.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double lowest = view.z.array().isNaN().select(kInf, view.z.array()).minCoeff();
    HeightMap map;
    map.z = view.z.array() - lowest;
    map.source = file.string();
    map.uncovered_height = 0.0;  // around the part: the floor, as low as its lowest visible surface
    return map;
  }
};

}  // namespace

std::vector<Triangle3d> load_mesh_triangles(const std::filesystem::path& file, const ImportOptions& options) {
  Assimp::Importer importer;
  auto* io = new ConfinedIOSystem(file);
  importer.SetIOHandler(io);  // the importer owns it
  const aiScene* scene = importer.ReadFile(file.string(), 0);
  if (!io->refused().empty())
    throw ImportError(file, "it names a file outside its upload, \"" + io->refused() +
                                "\": external buffers, images and material files must sit beside the mesh (no \"..\", "
                                "absolute paths or URIs)");
  if (scene == nullptr) throw ImportError(file, std::string("Assimp cannot read it: ") + importer.GetErrorString());
  if (scene->mNumMeshes == 0) throw ImportError(file, "it holds no meshes");
  // Instancing can multiply a small file: count before the copies are made.
  if (const long planned = triangles_after_processing(*scene, kMaxMeshTriangles); planned > kMaxMeshTriangles)
    throw ImportError(file, "at least " + std::to_string(planned) +
                                " triangles once every instance is placed, over the limit of " +
                                std::to_string(kMaxMeshTriangles));
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                       aiProcess_PreTransformVertices);
  if (scene == nullptr) throw ImportError(file, std::string("Assimp cannot process it: ") + importer.GetErrorString());
  const long n = count_triangles(*scene);
  if (n == 0) throw ImportError(file, "it holds no triangles (only points or lines)");
  if (n > kMaxMeshTriangles)
    throw ImportError(file, std::to_string(n) + " triangles is over the limit of " + std::to_string(kMaxMeshTriangles));

  // Every triangle, rotated so the chosen up axis is +z.
  auto [up_axis, up_negative] = std::make_pair(options.mesh_up_axis, options.mesh_up_negative);
  if (up_axis == 0) std::tie(up_axis, up_negative) = options.sidecar ? sidecar_up_axis(file).value_or(std::make_pair('z', false))
                                                                     : std::make_pair('z', false);
  std::vector<Triangle3d> triangles;
  triangles.reserve(size_t(n));
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& mesh = *scene->mMeshes[m];
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;
      Triangle3d& t = triangles.emplace_back();
      for (int k = 0; k < 3; ++k) {
        t[k] = to_z_up(mesh.mVertices[face.mIndices[k]], up_axis, up_negative);
        if (!t[k].allFinite())
          throw ImportError(file, "a vertex of mesh " + std::to_string(m) + " has a non-finite coordinate");
      }
    }
  }
  return triangles;
}

HJ_REGISTER_GOAL_IMPORTER(MeshImporter);

}  // namespace hj
