// A deterministic mutation fuzzer for the mesh readers (OFF, OBJ, ASCII PLY, binary PLY of both
// byte orders): valid seed files are mutated at random (bit flips, byte insertions and deletions,
// duplicated and truncated ranges, numbers replaced by extreme or malformed ones) and parsed from
// memory, then validated as a TriMesh. Every input must either parse or throw bendlab::Error: no
// other exception, and (under the debug preset's AddressSanitizer and UBSan) no crash, overflow or
// leak. The seed of the generator is fixed, so a failure reproduces; BENDLAB_FUZZ_INPUTS scales
// the budget (default 25000 inputs per seed, 125000 in all).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "bendlab/core/file_input.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "core/byte_mutation.hpp"

namespace fs = std::filesystem;
using namespace bendlab;

namespace {

long inputs_per_seed() {
  if (const char* s = std::getenv("BENDLAB_FUZZ_INPUTS")) return std::max(1L, std::atol(s));
  return 25000;
}

struct Seed {
  std::string format;
  std::string bytes;
};

std::vector<Seed> seeds() {
  const TriMesh m = icosahedron();  // the icosahedron: small, closed, valid
  const fs::path dir = fs::temp_directory_path() / ("bendlab_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::vector<Seed> out;
  for (const char* ext : {"off", "obj", "ply"}) {
    const fs::path p = dir / (std::string("seed.") + ext);
    write_mesh(p, m.topology(), m.positions());
    out.push_back({ext, read_regular_file(p)});
  }
  fs::remove_all(dir);
  out.push_back({"ply",
                 "ply\nformat ascii 1.0\ncomment tetrahedron\nelement vertex 4\nproperty float x\nproperty float y\n"
                 "property float z\nproperty uchar red\nelement face 4\nproperty list uchar int vertex_indices\n"
                 "end_header\n0 0 0 1\n1 0 0 2\n0 1 0 3\n0 0 1 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"});
  // Big-endian binary PLY of the same tetrahedron: float coordinates, uchar counts, int indices.
  std::string be = "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                   "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n";
  auto put_be = [&](std::uint32_t v) {
    for (int k = 3; k >= 0; --k) be.push_back(static_cast<char>((v >> (8 * k)) & 0xff));
  };
  const float xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& v : xyz)
    for (float c : v) {
      std::uint32_t bits;
      std::memcpy(&bits, &c, 4);
      put_be(bits);
    }
  const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& f : faces) {
    be.push_back(3);
    for (int i : f) put_be(static_cast<std::uint32_t>(i));
  }
  out.push_back({"ply", be});
  return out;
}

const std::vector<std::string> kTokens = {"-1", "0", "3", "4", "255", "65536", "2147483647", "-2147483648", "4294967296",
                               "1e308", "-1e308", "1e-320", "nan", "inf", "-inf", "0x10", "+", "-", ".", "e5",
                               "999999999999999999999", "\n", " ", "#", "/", "//", "ply", "end_header",
                               "element face 1000000000\n", "property list uchar int vertex_indices\n",
                               "format binary_little_endian 1.0\n", "property double x\n", "f 1 2\n", "v 1 2\n"};

std::string mutate(const std::string& seed, std::mt19937_64& rng) {
  return test::mutate_bytes(seed, rng, kTokens, " \n");
}

}  // namespace

TEST(MeshReaderFuzz, EveryMutatedInputParsesOrThrowsError) {
  const std::vector<Seed> all = seeds();
  ASSERT_EQ(all.size(), 5u);
  const long n = inputs_per_seed();
  std::mt19937_64 rng(20261201);
  long parsed = 0, refused = 0, valid_meshes = 0;
  for (const Seed& seed : all) {
    // The seed itself is a valid mesh.
    ASSERT_NO_THROW(parse_raw_mesh(seed.bytes, seed.format, "seed." + seed.format));
    for (long i = 0; i < n; ++i) {
      const std::string input = mutate(seed.bytes, rng);
      try {
        RawMesh raw = parse_raw_mesh(input, seed.format, "fuzz." + seed.format);
        ++parsed;
        // Whatever parses must also be validated safely (TriMesh refuses with MeshError).
        try {
          TriMesh mesh(std::move(raw.positions), raw.faces);
          ++valid_meshes;
        } catch (const Error&) {
        }
      } catch (const Error& e) {
        ++refused;
        ASSERT_NE(std::string(e.what()).find("fuzz." + seed.format), std::string::npos)
            << "a read error must name the file: " << e.what();
      } catch (const std::exception& e) {
        FAIL() << "seed " << seed.format << " input " << i << ": not a bendlab::Error: " << e.what();
      }
    }
  }
  // The mutations must exercise both outcomes, or the fuzzer tests nothing.
  EXPECT_GT(parsed, 0);
  EXPECT_GT(refused, 0);
  EXPECT_GT(valid_meshes, 0);
  std::cout << "[ info ] " << all.size() * n << " inputs: " << parsed << " parsed (" << valid_meshes
            << " valid meshes), " << refused << " refused\n";
}
