// VTK XML PolyData (.vtp), ascii DataArrays, as read by ParaView.
#include <fmt/format.h>

#include "mesh_io_detail.hpp"

namespace bendlab::io_detail {

void write_vtp(std::ostream& out, const Topology& topology, const Points& x, const VertexFields& fields) {
  TextWriter w(out);
  const Faces& F = topology.faces();
  w.print("<?xml version=\"1.0\"?>\n");
  w.print("<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n");
  w.print("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
          "NumberOfPolys=\"{}\">\n",
          x.rows(), F.rows());
  // The first field of each kind becomes ParaView's active scalar or vector.
  w.print("      <PointData");
  if (!fields.scalars.empty()) w.print(" Scalars=\"{}\"", fields.scalars.front().first);
  if (!fields.vectors.empty()) w.print(" Vectors=\"{}\"", fields.vectors.front().first);
  w.print(">\n");
  for (const auto& [name, values] : fields.scalars) {
    w.print("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"1\" format=\"ascii\">\n", name);
    for (Eigen::Index i = 0; i < values.size(); ++i) w.print("{:.17g}\n", values(i));
    w.print("        </DataArray>\n");
  }
  for (const auto& [name, values] : fields.vectors) {
    w.print("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"3\" format=\"ascii\">\n", name);
    for (Eigen::Index i = 0; i < values.rows(); ++i)
      w.print("{:.17g} {:.17g} {:.17g}\n", values(i, 0), values(i, 1), values(i, 2));
    w.print("        </DataArray>\n");
  }
  w.print("      </PointData>\n      <Points>\n");
  w.print("        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (Eigen::Index i = 0; i < x.rows(); ++i) w.print("{:.17g} {:.17g} {:.17g}\n", x(i, 0), x(i, 1), x(i, 2));
  w.print("        </DataArray>\n      </Points>\n      <Polys>\n");
  w.print("        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n");
  for (Eigen::Index f = 0; f < F.rows(); ++f) w.print("{} {} {}\n", F(f, 0), F(f, 1), F(f, 2));
  w.print("        </DataArray>\n");
  w.print("        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
  for (Eigen::Index f = 0; f < F.rows(); ++f) w.print("{}\n", 3 * (f + 1));
  w.print("        </DataArray>\n      </Polys>\n    </Piece>\n  </PolyData>\n</VTKFile>\n");
  w.flush();
}

}  // namespace bendlab::io_detail
