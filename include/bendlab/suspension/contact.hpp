#pragma once
// Short-range repulsion between the membranes of different cells and between a membrane and the
// vessel's wall (shared/spec/CELLS_IN_CHANNELS.md section 2; docs/conventions.md §6): without it
// cells cross walls and each other where the immersed boundary lets fluid leak between them.
//
// The law acts between vertices of different cells (and between a vertex and the wall) at a
// distance r below the cutoff r_c:
//   U(r) = F_max r_c / 3 (1 - r/r_c)^3,     F(r) = -dU/dr = F_max (1 - r/r_c)^2,
// repulsive, capped at F_max (r -> 0), zero with a zero slope at r_c and exactly zero beyond, so
// cells farther apart than r_c feel nothing and the force switches on smoothly. A vertex past the
// wall (r < 0) feels F_max towards the fluid. Vertices of one cell never repel each other: the
// membrane's own elasticity keeps its shape.
//
// Pairs are found with a uniform cell list of bins at least r_c wide; separations take the
// nearest periodic image (the image in the neighbour bin, or Vessel::minimum_image where an axis
// has fewer than three bins), so positions may be unwrapped. ContactSearch
// keeps its bins between calls: once warm it allocates nothing.
//
// Verlet list. add_cell_contact keeps the pairs of different cells closer than r_c + skin (skin =
// kSkinFraction r_c) and searches the bins again only when some vertex has moved more than skin / 2
// since (or the rows, their cells or the law changed): until then every pair closer than r_c is
// in the list. The forces are a function of the positions alone, bit for bit those of the search
// in every call (add_cell_contact_reference, kept as the reference), whenever the list was
// rebuilt.
#include <cstdint>
#include <utility>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/suspension/vessel.hpp"

namespace bendlab {

struct ContactLaw {
  double max_force = 0;  ///< F_max, the force at contact
  double cutoff = 0;     ///< r_c
  /// Throws bendlab::Error for a negative or non-finite force or a non-positive cutoff.
  void validate() const;
  double force(double r) const;
  double energy(double r) const;
};

/// Adds the wall's repulsion on every vertex of x to F; returns the energy sum_i U(d_i).
double add_wall_contact(const Vessel& vessel, const ContactLaw& law, const Points& x, Points& F);

class ContactSearch {
 public:
  /// Adds the repulsion between vertices of different cells (cell_of[i]: the cell of row i of x)
  /// to F; returns the energy summed over the pairs. Each vertex's force is added pair by pair in
  /// the order of its partners' rows, so it does not depend on vertices beyond the cutoff (nor on
  /// the bins they make): rows of x that keep their order and their neighbours give the same
  /// forces bit for bit (the MPI suspension holds only the cells near a rank's slab). A pair is
  /// found from both of its vertices, each adding its own side, so nothing is stored per pair
  /// (Newton's third law then holds to round-off: the two sides' separations are the nearest
  /// image taken from either end).
  double add_cell_contact(const Vessel& vessel, const ContactLaw& law, const Points& x,
                          const std::vector<int>& cell_of, Points& F);
  /// The same with the bins searched in every call and no list kept: the reference of the Verlet
  /// list. Forces equal add_cell_contact's bit for bit; the energy is summed in another order.
  double add_cell_contact_reference(const Vessel& vessel, const ContactLaw& law, const Points& x,
                                    const std::vector<int>& cell_of, Points& F);
  /// The Verlet list's skin as a fraction of the cutoff.
  static constexpr double kSkinFraction = 0.3;
  /// How often the pairs were searched for again (diagnostic; every call of the reference counts).
  std::int64_t list_builds() const { return list_builds_; }
  /// The smallest distance between vertices of different cells closer than `range` (range if
  /// none): a diagnostic of how near the cells came.
  double min_cell_distance(const Vessel& vessel, const Points& x, const std::vector<int>& cell_of, double range);

 private:
  // Bins the rows of x (bins at least `width` wide), with their positions wrapped into the period
  // and, in bin order, those positions and cells; the pairs then come from for_each_pair.
  void bin(const Vessel& vessel, const Points& x, const std::vector<int>& cell_of, double width);
  // visit(i, j, d, r) for the pairs closer than range, i < j (or every ordered pair with
  // kBothSides), grouped by i, with end_of_vertex(i) after each i's partners.
  template <bool kBothSides, class Visit, class EndOfVertex>
  void for_each_pair(const Vessel& vessel, const Points& x, const std::vector<int>& cell_of, double range, Visit&& visit,
                     EndOfVertex&& end_of_vertex);

  int nb_[3] = {0, 0, 0};
  double lo_[3] = {0, 0, 0}, w_[3] = {1, 1, 1};
  static constexpr int kEmptyBin = -1, kMixedBin = -2;
  std::vector<int> bin_of_, start_, items_, sorted_cell_, bin_cell_;
  struct Partner {
    int row;  // j
    Vec3 d;   // x_i - x_j (nearest image)
    double r;
  };
  std::vector<Partner> partners_;  // of one vertex i
  Points wrapped_, sorted_;
  // The Verlet list: the partners of row i are list_row_[list_start_[i] .. list_start_[i + 1]),
  // ascending, found at the positions list_x_ (unwrapped) with the cells list_cell_.
  bool list_is_current(const Vessel& vessel, const ContactLaw& law, const Points& x, const std::vector<int>& cell_of) const;
  void build_list(const Vessel& vessel, const ContactLaw& law, const Points& x, const std::vector<int>& cell_of);
  std::vector<int> list_start_, list_row_, list_cell_;
  std::vector<int> fill_;  // each row's next free place while building
  Points list_x_;
  double list_cutoff_ = 0;
  Vec3 list_period_ = Vec3::Zero();
  std::int64_t list_builds_ = 0;
};

}  // namespace bendlab
