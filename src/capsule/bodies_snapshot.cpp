#include "bendlab/capsule/bodies_snapshot.hpp"

#include <fmt/format.h>

#include "bendlab/core/atomic_file.hpp"
#include "bendlab/mesh/mesh_io.hpp"

namespace bendlab {

void write_bodies_snapshot(const std::filesystem::path& path, const std::vector<SolverBody>& bodies, const Points& x) {
  if (bodies.size() == 1 && bodies.front().first_row == 0 && bodies.front().membrane->num_vertices() == x.rows()) {
    write_mesh(path, bodies.front().membrane->topology(), x);
    return;
  }
  if (bodies.empty()) {
    // No body (a flow without cells): an empty piece, which ParaView shows as nothing.
    if (x.rows() != 0) throw Error(fmt::format("snapshot '{}': {} positions for no body", path.string(), x.rows()));
    AtomicFile f(path);
    f.stream() << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
                  "  <PolyData>\n    <Piece NumberOfPoints=\"0\" NumberOfVerts=\"0\" NumberOfLines=\"0\" "
                  "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
    f.commit();
    return;
  }
  Eigen::Index faces = 0, rows = 0;
  for (const SolverBody& b : bodies) {
    if (b.first_row != rows)
      throw Error(fmt::format("snapshot '{}': body rows are not consecutive (row {}, expected {})", path.string(),
                              b.first_row, rows));
    faces += b.membrane->topology().num_faces();
    rows += b.membrane->num_vertices();
  }
  if (rows != x.rows())
    throw Error(fmt::format("snapshot '{}': {} positions for bodies of {} vertices", path.string(), x.rows(), rows));
  Faces joint(faces, 3);
  Eigen::VectorXd body(rows);
  Eigen::Index f = 0;
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const SolverBody& b = bodies[k];
    const Faces& own = b.membrane->topology().faces();
    joint.middleRows(f, own.rows()) = own.array() + static_cast<int>(b.first_row);
    f += own.rows();
    body.segment(b.first_row, b.membrane->num_vertices()).setConstant(static_cast<double>(k));
  }
  VertexFields fields;
  fields.scalars.emplace_back("body", body);
  write_mesh(path, *Topology::build(static_cast<int>(rows), joint), x, fields);
}

}  // namespace bendlab
