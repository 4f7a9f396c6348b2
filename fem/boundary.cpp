#include "fem/boundary.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>

#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

std::string trim(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      parts.push_back(trim(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  parts.push_back(trim(cur));
  return parts;
}

bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  std::size_t used = 0;
  try {
    v = std::stod(s, &used);
  } catch (...) {
    return false;
  }
  return used == s.size() && std::isfinite(v);
}

// A positive id written as an integer: "3" but not "3.0", "+3" or "3e0".
bool parse_id(const std::string& s, int& v) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  v = std::stoi(s);
  return v > 0;
}

[[noreturn]] void bad(const std::string& spec, const std::string& why) {
  throw Error("--fix '" + spec + "': " + why);
}

std::vector<std::uint8_t> used_nodes(const MixedMesh& mesh) {
  std::vector<std::uint8_t> used(mesh.nodes.size(), 0);
  for (std::int32_t v : mesh.cell_nodes)
    if (v >= 0) used[v] = 1;
  for (std::int32_t v : mesh.cell_edge_nodes)  // order 2
    if (v >= 0) used[v] = 1;
  return used;
}

// Nodes of the boundary faces for which `take(face)` holds.
template <class Pred>
std::vector<std::int32_t> face_nodes(const MixedMesh& mesh, Pred take) {
  std::vector<std::int32_t> nodes;
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f)
    if (take(f))
      for (int q = 0; q < 4; ++q) {
        if (mesh.bface(f)[q] >= 0) nodes.push_back(mesh.bface(f)[q]);
        if (mesh.order == 2 && mesh.bface_edge_nodes[4 * f + q] >= 0)
          nodes.push_back(mesh.bface_edge_nodes[4 * f + q]);
      }
  return nodes;
}

std::string id_list(const std::set<int>& ids) {
  std::ostringstream s;
  int shown = 0;
  for (int id : ids) {
    if (shown++ == 20) {
      s << " ...";
      break;
    }
    s << (shown > 1 ? "," : "") << id;
  }
  return ids.empty() ? "none" : s.str();
}

}  // namespace

FixSpec parse_fix_spec(const std::string& spec_in) {
  const std::string spec = trim(spec_in);
  FixSpec out;
  std::string selector = spec;
  if (const auto at = spec.rfind('@'); at != std::string::npos) {
    selector = trim(spec.substr(0, at));
    const std::string comps = trim(spec.substr(at + 1));
    if (comps.empty()) bad(spec, "no component after '@' (use e.g. @z or @xy)");
    for (int a = 0; a < 3; ++a) out.component[a] = false;
    for (char c : comps) {
      if (c < 'x' || c > 'z') bad(spec, std::string("unknown component '") + c + "' (x, y or z)");
      out.component[c - 'x'] = true;
    }
  }
  if (selector.empty()) bad(spec, "empty selector");
  if (selector.rfind("face:", 0) == 0) {
    for (const std::string& tok : split(selector.substr(5), ',')) {
      int id;
      if (!parse_id(tok, id)) bad(spec, "'" + tok + "' is not a CAD-face id (1, 2, ...)");
      out.faces.push_back(id);
    }
    return out;
  }
  if (selector.rfind("group:", 0) == 0) {
    out.kind = FixSpec::Kind::Group;
    out.group = trim(selector.substr(6));
    if (out.group.empty()) bad(spec, "no group name or tag after 'group:'");
    return out;
  }
  out.kind = FixSpec::Kind::Coordinates;
  for (const std::string& c : split(selector, '&')) {
    if (c.size() < 3 || c[0] < 'x' || c[0] > 'z')
      bad(spec, "cannot parse '" + c + "' (expected face:IDS, group:NAME or e.g. x<0.001)");
    FixSpec::Condition cond{c[0] - 'x', "", 0};
    std::size_t p = 1;
    while (p < c.size() && std::isspace(static_cast<unsigned char>(c[p]))) ++p;
    while (p < c.size() && (c[p] == '<' || c[p] == '>' || c[p] == '=')) cond.op += c[p++];
    if (cond.op != "<" && cond.op != "<=" && cond.op != ">" && cond.op != ">=")
      bad(spec, "'" + c + "': operator must be <, <=, > or >=");
    if (!parse_double(trim(c.substr(p)), cond.value))
      bad(spec, "'" + c + "': '" + trim(c.substr(p)) + "' is not a number");
    out.conditions.push_back(cond);
  }
  return out;
}

namespace {

bool holds(const FixSpec::Condition& c, double x) {
  return c.op == "<"    ? x < c.value
         : c.op == "<=" ? x <= c.value
         : c.op == ">"  ? x > c.value
                        : x >= c.value;
}

std::string node_range(const MixedMesh& mesh, const std::vector<std::uint8_t>& used) {
  std::ostringstream range;
  for (int a = 0; a < 3; ++a) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
      if (used[i]) {
        lo = std::min(lo, mesh.nodes[i][a]);
        hi = std::max(hi, mesh.nodes[i][a]);
      }
    range << (a ? ", " : "") << char('x' + a) << " in [" << lo << ", " << hi << "]";
  }
  return range.str();
}

}  // namespace

NodeSelection select_fixed_nodes(const MixedMesh& mesh, const std::string& spec_in) {
  const std::string spec = trim(spec_in);
  const FixSpec fs = parse_fix_spec(spec);
  NodeSelection sel;
  std::copy(fs.component, fs.component + 3, sel.component);
  std::vector<std::int32_t> nodes;
  if (fs.kind == FixSpec::Kind::Faces) {
    const std::set<int> wanted(fs.faces.begin(), fs.faces.end());
    nodes = face_nodes(mesh, [&](std::size_t f) { return wanted.count(mesh.bface_cad_face[f]); });
    if (nodes.empty()) {
      const std::set<int> present(mesh.bface_cad_face.begin(), mesh.bface_cad_face.end());
      bad(spec,
          "no boundary face has this CAD-face id (ids in the mesh: " + id_list(present) + ")");
    }
  } else if (fs.kind == FixSpec::Kind::Group) {
    std::set<int> tags;
    int tag;
    if (parse_id(fs.group, tag)) tags.insert(tag);
    for (const auto& [key, value] : mesh.physical_names)
      if (key.first == 2 && value == fs.group) tags.insert(key.second);
    nodes = face_nodes(mesh, [&](std::size_t f) { return tags.count(mesh.bface_physical[f]); });
    if (nodes.empty()) {
      const std::set<int> present(mesh.bface_physical.begin(), mesh.bface_physical.end());
      bad(spec, "no boundary face is in this physical group (surface tags in the mesh: " +
                    id_list(present) + ")");
    }
  } else {
    const std::vector<std::uint8_t> used = used_nodes(mesh);
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
      bool ok = used[i];
      for (const FixSpec::Condition& c : fs.conditions) ok = ok && holds(c, mesh.nodes[i][c.axis]);
      if (ok) nodes.push_back(static_cast<std::int32_t>(i));
    }
    if (nodes.empty()) bad(spec, "selects no node (mesh nodes: " + node_range(mesh, used) + ")");
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  sel.nodes = std::move(nodes);
  return sel;
}

std::vector<std::uint8_t> select_fixed_dofs(const MixedMesh& mesh,
                                            const std::vector<std::string>& specs) {
  std::vector<std::uint8_t> fixed(3 * mesh.nodes.size(), 0);
  for (const std::string& spec : specs) {
    const NodeSelection sel = select_fixed_nodes(mesh, spec);
    for (std::int32_t v : sel.nodes)
      for (int a = 0; a < 3; ++a)
        if (sel.component[a]) fixed[3 * v + a] = 1;
  }
  return fixed;
}

DofMap number_free_dofs(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                        const std::vector<std::int32_t>& node_order) {
  const std::size_t n = mesh.nodes.size();
  if (fixed.size() != 3 * n) throw Error("number_free_dofs: mask size does not match the mesh");
  if (!node_order.empty() && node_order.size() != n)
    throw Error("number_free_dofs: node order size does not match the mesh");
  const std::vector<std::uint8_t> used = used_nodes(mesh);
  DofMap map;
  map.ties = nc_face_ties(mesh, fixed);
  map.dof.assign(3 * n, -1);
  map.node_rank.resize(n);
  for (std::size_t r = 0; r < n; ++r) {
    const std::int32_t v = node_order.empty() ? static_cast<std::int32_t>(r) : node_order[r];
    map.node_rank[v] = static_cast<std::int32_t>(r);
    if (!used[v] || map.ties.tied(v)) continue;
    for (int a = 0; a < 3; ++a) {
      if (fixed[3 * v + a])
        ++map.num_fixed;
      else
        map.dof[3 * v + a] = map.num_free++;
    }
  }
  return map;
}

Eigen::VectorXd expand_to_nodes(const DofMap& map, const Eigen::VectorXd& reduced) {
  Eigen::VectorXd full = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(map.dof.size()));
  for (std::size_t i = 0; i < map.dof.size(); ++i)
    if (map.dof[i] >= 0) full[static_cast<Eigen::Index>(i)] = reduced[map.dof[i]];
  fill_tied_nodes(map.ties, full.data());
  return full;
}

UnheldRigidMotions unheld_rigid_motions(const MixedMesh& mesh,
                                        const std::vector<std::uint8_t>& fixed) {
  // Centre and scale the coordinates so translations and rotations weigh alike.
  const std::vector<std::uint8_t> used = used_nodes(mesh);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (!used[i]) continue;
    const Eigen::Vector3d x(mesh.nodes[i][0], mesh.nodes[i][1], mesh.nodes[i][2]);
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double length = std::max((hi - lo).norm(), std::numeric_limits<double>::min());

  // Rows of the rigid-motion basis at one fixed DOF (node i, component a): translation e_a and
  // rotations r_k = e_k x (x - c) / L, whose component a is (e_k x d)_a.
  Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (!used[i]) continue;
    const Eigen::Vector3d d =
        (Eigen::Vector3d(mesh.nodes[i][0], mesh.nodes[i][1], mesh.nodes[i][2]) - centre) / length;
    for (int a = 0; a < 3; ++a) {
      if (!fixed[3 * i + a]) continue;
      Eigen::Matrix<double, 6, 1> row = Eigen::Matrix<double, 6, 1>::Zero();
      row[a] = 1;
      for (int k = 0; k < 3; ++k) row[3 + k] = Eigen::Vector3d::Unit(k).cross(d)[a];
      gram += row * row.transpose();
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(gram);
  const double top = eig.eigenvalues().maxCoeff();
  UnheldRigidMotions out;
  out.centre = centre;
  out.length = length;
  int unheld = 0;
  for (int k = 0; k < 6; ++k) unheld += !(eig.eigenvalues()[k] > 1e-10 * top);
  out.coefficients = eig.eigenvectors().leftCols(unheld);  // eigenvalues ascend
  return out;
}

int count_unheld_rigid_motions(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed) {
  return static_cast<int>(unheld_rigid_motions(mesh, fixed).coefficients.cols());
}

std::vector<std::int32_t> connected_parts(const MixedMesh& mesh, const NodeTies& ties,
                                          std::int32_t* count) {
  const std::size_t nn = mesh.nodes.size();
  std::vector<std::int32_t> parent(nn);
  for (std::size_t v = 0; v < nn; ++v) parent[v] = static_cast<std::int32_t>(v);
  auto find = [&parent](std::int32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  auto join = [&](std::int32_t a, std::int32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the smallest id is the root
  };
  std::vector<std::uint8_t> used(nn, 0);
  std::int32_t ids[64];
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const int n = mesh.element_nodes(c, ids);
    for (int i = 0; i < n; ++i) {
      used[ids[i]] = 1;
      join(ids[0], ids[i]);
    }
  }
  for (std::size_t v = 0; v < ties.slot.size(); ++v)
    if (ties.slot[v] >= 0)
      for (int i = 0; i < kTieMasters; ++i)
        if (ties.weight[kTieMasters * ties.slot[v] + i] != 0)
          join(static_cast<std::int32_t>(v), ties.master[kTieMasters * ties.slot[v] + i]);
  // Numbered in the order of their smallest node, so the numbering is deterministic.
  std::vector<std::int32_t> part(nn, -1);
  std::int32_t parts = 0;
  for (std::size_t v = 0; v < nn; ++v) {
    if (!used[v]) continue;
    const std::int32_t r = find(static_cast<std::int32_t>(v));
    if (part[r] < 0) part[r] = parts++;
    part[v] = part[r];
  }
  if (count) *count = parts;
  return part;
}

void check_every_part_is_held(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed) {
  if (std::none_of(fixed.begin(), fixed.end(), [](std::uint8_t f) { return f != 0; })) return;
  std::int32_t count = 0;
  const std::vector<std::int32_t> part = connected_parts(mesh, NodeTies{}, &count);
  if (count < 2) return;
  std::vector<std::uint8_t> held(static_cast<std::size_t>(count), 0);
  std::vector<long> nodes(static_cast<std::size_t>(count), 0);
  std::vector<Vec3> first(static_cast<std::size_t>(count));
  for (std::size_t v = 0; v < part.size(); ++v) {
    if (part[v] < 0) continue;
    const auto p = static_cast<std::size_t>(part[v]);
    if (nodes[p]++ == 0) first[p] = mesh.nodes[v];
    for (int a = 0; a < 3; ++a) held[p] = held[p] || fixed[3 * v + a];
  }
  for (std::size_t p = 0; p < held.size(); ++p)
    if (!held[p]) {
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "the fixed set does not touch part %zu of the mesh's %d unconnected parts (%ld "
                    "nodes, one at (%g, %g, %g)): it is free to move; fix it too, or join the "
                    "solids into one",
                    p + 1, count, nodes[p], first[p][0], first[p][1], first[p][2]);
      throw Error(buf);
    }
}

Eigen::MatrixXd rigid_motions_of_parts(const MixedMesh& mesh, const DofMap& dofs) {
  if (dofs.num_fixed > 0 || dofs.num_free == 0) return {};
  const std::size_t nn = mesh.nodes.size();
  std::int32_t count = 0;
  const std::vector<std::int32_t> part = connected_parts(mesh, dofs.ties, &count);
  const auto np = static_cast<std::size_t>(count);
  std::vector<Eigen::Vector3d> lo(np, Eigen::Vector3d::Constant(1e300)),
      hi(np, Eigen::Vector3d::Constant(-1e300));
  for (std::size_t v = 0; v < nn; ++v)
    if (part[v] >= 0) {
      const Eigen::Vector3d x(mesh.nodes[v][0], mesh.nodes[v][1], mesh.nodes[v][2]);
      lo[part[v]] = lo[part[v]].cwiseMin(x);
      hi[part[v]] = hi[part[v]].cwiseMax(x);
    }
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(dofs.num_free, 6 * static_cast<long>(np));
  for (std::size_t v = 0; v < nn; ++v) {
    const std::int32_t p = part[v];
    if (p < 0) continue;
    const Eigen::Vector3d centre = 0.5 * (lo[p] + hi[p]);
    const double length = std::max((hi[p] - lo[p]).maxCoeff(), 1e-300);
    const Eigen::Vector3d d =
        (Eigen::Vector3d(mesh.nodes[v][0], mesh.nodes[v][1], mesh.nodes[v][2]) - centre) / length;
    for (int b = 0; b < 3; ++b) {
      const std::int32_t row = dofs.dof[3 * v + b];
      if (row < 0) continue;
      R(row, 6 * p + b) = 1;
      for (int k = 0; k < 3; ++k) R(row, 6 * p + 3 + k) = Eigen::Vector3d::Unit(k).cross(d)[b];
    }
  }
  return R;
}

}  // namespace hexfem
