#pragma once
// Triangle mesh files: reading OFF, OBJ and PLY; writing OFF, OBJ, PLY and VTK XML PolyData (.vtp),
// plus ParaView collections (.pvd) that make a time series of .vtp files.
//
// Formats are chosen by the file extension, case-insensitively.
//
// Reading
// - OFF: an "OFF" header line (the variants COFF, NOFF, STOFF, ... are accepted: the extra values
//   they put on a vertex or face line are ignored), a counts line "nv nf [ne]", then one vertex
//   per line (x y z, further values ignored) and one face per line ("n i_0 ... i_{n-1}", further
//   values such as colours ignored). '#' starts a comment up to the end of the line. Binary OFF
//   is refused. Nothing but comments may follow the last face.
// - OBJ: "v x y z [w]" and "f" lines; a face corner may be "i", "i/t", "i//n" or "i/t/n", and a
//   negative i counts back from the last vertex read so far (-1 = that vertex). Every other line
//   type (vn, vt, g, o, s, usemtl, l, ...) is ignored.
// - PLY: ascii, binary_little_endian and binary_big_endian; scalar types char/uchar/short/ushort/
//   int/uint/float/double or int8/uint8/int16/uint16/int32/uint32/float32/float64. The element
//   "vertex" must have properties x, y, z (of any scalar type; other properties are skipped);
//   the element "face" must have a list property "vertex_indices" or "vertex_index" (any count
//   and index types; other properties are skipped). Every other element is skipped.
// - Polygons with more than three corners are fan-triangulated: (v0, v_k, v_{k+1}), which keeps
//   the polygon's orientation.
// - Faces are stored with 0-based indices exactly as given (no reordering, no merging).
//
// Errors: a file that cannot be read or parsed throws bendlab::Error with a one-line message that
// names the file, the position (line number for text, byte offset and element index for binary
// PLY) and the problem. Declared counts are checked against the file size before anything is
// allocated. A negative or unparsable index is a read error; an index past the last vertex is not
// (read_raw_mesh returns it, and TriMesh validation refuses it with MeshError::IndexOutOfRange).
// Nothing is returned unless the whole file was read.
//
// Writing: every file goes through AtomicFile, so a failed write leaves no file (and an existing
// target untouched). Coordinates and fields are written with 17 significant digits in the text
// formats (a write-read round trip is exact) and as float64 in binary PLY.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"
#include "bendlab/mesh/trimesh.hpp"

namespace bendlab {

/// Named per-vertex data to write next to the shape: scalars (N values) and vectors (N x 3).
/// Names must be non-empty, made of printable ASCII without spaces or any of < > & " ', distinct
/// from each other and from x, y, z and from the component names (name_x, ...) of vector fields.
struct VertexFields {
  std::vector<std::pair<std::string, Scalars>> scalars;
  std::vector<std::pair<std::string, Points>> vectors;
};

/// A mesh as it stands in a file, not validated: positions (N x 3) and 0-based triangles (F x 3).
struct RawMesh {
  Points positions;
  Faces faces;
};

/// Reads a .off, .obj or .ply file (see above). Only regular files are read (a FIFO, device or
/// folder is refused at once); I/O errors give the operating system's reason. Throws bendlab::Error.
RawMesh read_raw_mesh(const std::filesystem::path& path);

/// Parses the bytes of a mesh file held in memory; format is "off", "obj" or "ply", and `name`
/// stands for the file in error messages. Throws bendlab::Error as read_raw_mesh.
RawMesh parse_raw_mesh(const std::string& bytes, const std::string& format, const std::filesystem::path& name);

/// read_raw_mesh, then TriMesh validation. Throws bendlab::Error for a file that cannot be read
/// and MeshError (whose message then also names the file) for a mesh that TriMesh refuses.
TriMesh read_mesh(const std::filesystem::path& path, MeshOptions options = {});

/// Writes the mesh (topology, positions x) to a .off, .obj, .ply or .vtp file, chosen by extension.
/// - .off: ascii OFF. .obj: "v" and "f" lines (1-based indices).
/// - .ply: binary_little_endian; vertex properties double x, y, z, then one double property per
///   scalar field and three (name_x, name_y, name_z) per vector field; faces as
///   "list uchar int vertex_indices".
/// - .vtp: VTK XML PolyData (ascii), Float64 Points, Int32 Polys connectivity and Int64 offsets,
///   and one Float64 PointData DataArray per field (NumberOfComponents 1 or 3).
/// Fields are written to .ply and .vtp only, and ignored for .off and .obj.
/// Throws bendlab::Error for an unknown extension, x or a field with a row count other than the
/// number of vertices, a bad field name, or a failed write (leaving no file behind).
void write_mesh(const std::filesystem::path& path, const Topology& topology, const Points& x,
                const VertexFields& fields = {});

/// Writes a ParaView collection (.pvd) listing (time, file) pairs in the given order. File names
/// are written as given; ParaView resolves relative names against the folder of the .pvd, so
/// pass names relative to it. Throws bendlab::Error for a non-finite time or a failed write.
void write_pvd(const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& time_and_file);

}  // namespace bendlab
