// Mesh goals from hostile uploads: a glTF or OBJ that names a file outside
// its upload ("..", an absolute path, a URI) is refused, also through the
// server; instancing that would multiply a small file past the triangle
// limit is refused before the copies are made.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <fstream>

#include "expect_error.h"
#include "scratch_dir.h"
#include "server_fixture.h"
#include "shapes/goal_importer.h"
#include "shapes/mesh_importer.h"

namespace hj {
namespace {

using namespace testing_support;

// Triangles as float32 positions, one after another (non-indexed).
std::string positions(int triangles) {
  std::string bytes;
  for (int t = 0; t < triangles; ++t) {
    // Tilted so it is seen from every axis.
    const float x = float(t % 100), y = float(t / 100);
    const float v[9] = {x, y, 0, x + 1, y, 1, x, y + 1, 1};
    bytes.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  return bytes;
}

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    unsigned n = unsigned(std::uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) n |= unsigned(std::uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) n |= unsigned(std::uint8_t(bytes[i + 2]));
    out += digits[(n >> 18) & 63];
    out += digits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? digits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? digits[n & 63] : '=';
  }
  return out;
}

// A glTF of `triangles` triangles in one mesh placed by `instances` nodes,
// its buffer at `uri`.
std::string gltf(const std::string& uri, int triangles, int instances = 1) {
  const int bytes = triangles * 36;
  std::string nodes, refs;
  for (int i = 0; i < instances; ++i) {
    nodes += std::string(i ? "," : "") + "{\"mesh\":0}";
    refs += std::string(i ? "," : "") + std::to_string(i);
  }
  return "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"" + uri + "\",\"byteLength\":" +
         std::to_string(bytes) + "}],\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":" +
         std::to_string(bytes) + "}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" +
         std::to_string(3 * triangles) + ",\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[101,101,1]}]," +
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[" + nodes +
         "],\"scenes\":[{\"nodes\":[" + refs + "]}],\"scene\":0}";
}

void write(const std::filesystem::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary) << bytes;
}

TEST(MeshImportSafety, AGltfBufferBesideTheMeshImportsAndOneOutsideIsRefused) {
  ScratchDir dir;
  std::filesystem::create_directories(dir.path / "upload");
  write(dir.path / "upload" / "inside.bin", positions(1));
  write(dir.path / "beside.bin", positions(1));
  write(dir.path / "upload" / "good.gltf", gltf("inside.bin", 1));
  EXPECT_NO_THROW(import_goal(dir.path / "upload" / "good.gltf"));
  const std::string outside = (dir.path / "beside.bin").string();
  for (const std::string& uri : {std::string("../beside.bin"), outside, "file://" + outside}) {
    SCOPED_TRACE(uri);
    write(dir.path / "upload" / "bad.gltf", gltf(uri, 1));
    expect_error<ImportError>([&] { import_goal(dir.path / "upload" / "bad.gltf"); },
                              {"bad.gltf", "outside its upload", "beside.bin"});
  }
}

TEST(MeshImportSafety, AnObjMaterialLibraryOutsideTheFolderIsRefused) {
  ScratchDir dir;
  std::filesystem::create_directories(dir.path / "upload");
  write(dir.path / "secret.mtl", "newmtl m\nKd 1 0 0\n");
  write(dir.path / "upload" / "part.obj", "mtllib ../secret.mtl\nv 0 0 0\nv 1 0 1\nv 0 1 1\nusemtl m\nf 1 2 3\n");
  expect_error<ImportError>([&] { import_goal(dir.path / "upload" / "part.obj"); },
                            {"part.obj", "outside its upload", "secret.mtl"});
}

TEST(MeshImportSafety, InstancesPastTheTriangleLimitAreRefusedBeforeTheyAreCopied) {
  ScratchDir dir;
  const int triangles = 5000, instances = int(kMaxMeshTriangles / triangles) + 1;
  write(dir.path / "many.gltf",
        gltf("data:application/octet-stream;base64," + base64(positions(triangles)), triangles, instances));
  expect_error<ImportError>([&] { import_goal(dir.path / "many.gltf"); },
                            {"many.gltf", "once every instance is placed", std::to_string(kMaxMeshTriangles)});
}

// Through the server: the upload's buffer URI points at a file beside the
// server's temporary folder.
TEST(MeshImportSafety, TheServerRefusesAnUploadNamingAFileBesideIt) {
  ScratchDir dir;
  const auto beside = std::filesystem::temp_directory_path() / ("hj-beside-" + std::to_string(::getpid()) + ".bin");
  write(beside, positions(1));
  server::ServerOptions o;
  o.db_file = (dir.path / "q.db").string();
  TestServer s(o, false);
  for (const std::string& uri : {"../" + beside.filename().string(), beside.filename().string(), beside.string()}) {
    SCOPED_TRACE(uri);
    v1::PreviewRequest request = preview_request(2, 2);
    request.mutable_goal()->mutable_file()->set_content(gltf(uri, 1));
    request.mutable_goal()->mutable_file()->set_file_name("part.gltf");
    v1::PreviewResponse response;
    const grpc::Status status = s.planning->Preview(call().get(), request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
    EXPECT_NE(status.error_message().find("part.gltf"), std::string::npos) << status.error_message();
  }
  std::filesystem::remove(beside);
}

}  // namespace
}  // namespace hj
