// Dirichlet conditions: selecting the fixed DOFs from text specs, and eliminating them (the
// free DOFs are numbered, the fixed ones get no equation: no penalty, no spurious modes).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fem/nc_ties.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// One --fix spec: `selector[@components]`.
//   selector  face:3,7        nodes of the boundary faces with these CAD-face ids
//             group:NAME|TAG  nodes of the boundary faces in this physical group (name or tag)
//             x<0.001         nodes whose coordinate satisfies every condition of a
//             z<1e-3&x>9.999  '&'-joined list; coordinate x|y|z, operator < <= > >=, in the
//                             mesh's own units (as in the file, before any --units scaling)
//   components  which displacement components to fix, e.g. @z or @xy; default all three.
// Only nodes used by cells are selected. Returns the selected nodes (sorted) and components.
struct NodeSelection {
  std::vector<std::int32_t> nodes;
  bool component[3] = {true, true, true};
};
NodeSelection select_fixed_nodes(const MixedMesh& mesh, const std::string& spec);

// A --fix spec parsed without a mesh: the one parser of the syntax above, used by the solver
// and by the CLI (which checks CAD-face ids before meshing). A face id is a positive integer
// written as one ("face:3.0" is refused). Throws hexfem::Error naming the spec.
struct FixSpec {
  enum class Kind { Faces, Group, Coordinates };
  struct Condition {
    int axis;        // 0, 1, 2 for x, y, z
    std::string op;  // <, <=, > or >=
    double value;
  };
  Kind kind = Kind::Faces;
  std::vector<int> faces;             // Faces
  std::string group;                  // Group: a name, or a tag when all digits
  std::vector<Condition> conditions;  // Coordinates: all must hold
  bool component[3] = {true, true, true};
};
FixSpec parse_fix_spec(const std::string& spec);

// Per-DOF mask (3*i+a for node i, component a) of the union of all specs. Throws
// hexfem::Error when a spec cannot be parsed or selects no node.
std::vector<std::uint8_t> select_fixed_dofs(const MixedMesh& mesh,
                                            const std::vector<std::string>& specs);

// Equation numbers of the free DOFs: dof[3*i+a] = equation, or -1 when the DOF is fixed or its
// node belongs to no cell. Equations follow `node_order` (a permutation of the nodes; empty
// means 0..n-1), so a fill-reducing order of the nodes becomes the order of the matrix.
// At order 2 the hanging mid-edge nodes of NC quad faces are tied (nc_ties.hpp): they carry no
// equation (dof -1, counted neither free nor fixed) and follow their masters.
struct DofMap {
  std::vector<std::int32_t> dof;
  std::vector<std::int32_t> node_rank;  // position of each node in the order
  std::int32_t num_free = 0;
  std::int32_t num_fixed = 0;  // fixed DOFs of nodes that belong to cells
  NodeTies ties;
};
DofMap number_free_dofs(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                        const std::vector<std::int32_t>& node_order = {});

// How many of the six rigid-body motions (three translations, three rotations) the fixed DOFs
// do not hold: 0 for a clamped face, 3 for one fixed node, 1 for nodes on a line (rotation
// about it), etc. Judged on the rigid motions restricted to the fixed DOFs (the rank of their
// 6x6 Gram matrix), so it needs no solve. Nodes that belong to no cell are ignored.
int count_unheld_rigid_motions(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed);

// The unheld rigid motions themselves: column j of `coefficients` (6 x count) combines the
// translations e_a and the rotations e_k x (x - centre) / length into a motion that no fixed DOF
// resists (exactly a zero-energy mode of the constrained model).
struct UnheldRigidMotions {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double length = 1;
  Eigen::MatrixXd coefficients;
};
UnheldRigidMotions unheld_rigid_motions(const MixedMesh& mesh,
                                        const std::vector<std::uint8_t>& fixed);

// The connected part of each node (-1 for a node of no cell): cells join their nodes, NC-face
// ties join a tied node to its masters. Parts are numbered by their smallest node; `count` gets
// how many there are.
std::vector<std::int32_t> connected_parts(const MixedMesh& mesh, const NodeTies& ties,
                                          std::int32_t* count = nullptr);

// With some DOF fixed, every connected part must have one: a part the fixed set does not touch
// (a second solid of an assembly meshed apart) would come out as six zero modes. Throws
// hexfem::Error naming the first such part.
void check_every_part_is_held(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed);

// The six rigid-body motions of each connected part of a structure with no fixed DOF (parts
// joined by cells or by NC-face ties), as columns over the free DOFs: exact zero-energy modes.
// Empty when any DOF is fixed. The direct eigensolver deflates them (modal_solver.cpp): a
// single-vector Lanczos finds a six-fold (or 6p-fold) zero eigenvalue only through round-off,
// and missed one of them in some runs.
Eigen::MatrixXd rigid_motions_of_parts(const MixedMesh& mesh, const DofMap& dofs);

// Full nodal vector (3 * nodes, zeros at eliminated DOFs, tied nodes from their masters) from a
// vector of free DOFs.
Eigen::VectorXd expand_to_nodes(const DofMap& map, const Eigen::VectorXd& reduced);

}  // namespace hexfem
