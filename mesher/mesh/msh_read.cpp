// Gmsh MSH reader: 4.1 ASCII and binary, 2.2 ASCII. Only first-order elements.
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {

namespace {

// A cursor over the whole file that knows its line number, for error messages.
class Cursor {
 public:
  Cursor(std::string data, std::string name) : data_(std::move(data)), name_(std::move(name)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(name_ + ":" + std::to_string(line_) + ": " + what);
  }
  bool at_end() {
    skip_space();
    return pos_ >= data_.size();
  }
  std::string_view token() {
    skip_space();
    if (pos_ >= data_.size()) {
      line_ = token_line_;  // name the last line that had content
      fail("unexpected end of file (truncated mesh?)");
    }
    token_line_ = line_;
    const std::size_t start = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    return std::string_view(data_).substr(start, pos_ - start);
  }
  template <class T>
  T number(const char* what) {
    const std::string_view t = token();
    T value{};
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (ec != std::errc() || ptr != t.data() + t.size())
      fail(std::string("expected ") + what + ", found '" + std::string(t.substr(0, 40)) + "'");
    return value;
  }
  long integer(const char* what) { return number<long>(what); }
  double real(const char* what) { return number<double>(what); }
  void expect(std::string_view word) {
    const std::string_view t = token();
    if (t != word)
      fail("expected '" + std::string(word) + "', found '" + std::string(t.substr(0, 40)) + "'");
  }
  // Rest of the current line (used for quoted physical names).
  std::string rest_of_line() {
    const std::size_t start = pos_;
    while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
    return data_.substr(start, pos_ - start);
  }
  // Binary payloads follow the line break after a section header or count line.
  void skip_one_newline() {
    if (pos_ < data_.size() && data_[pos_] == '\r') ++pos_;
    if (pos_ < data_.size() && data_[pos_] == '\n') {
      ++pos_;
      ++line_;
    }
  }
  template <class T>
  T binary() {
    if (pos_ + sizeof(T) > data_.size()) fail("unexpected end of binary data (truncated mesh?)");
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  // Skips a section whose name we do not use, up to its $End line.
  void skip_section(std::string_view name) {
    const std::string end = "$End" + std::string(name.substr(1));
    const std::size_t at = data_.find(end, pos_);
    if (at == std::string::npos) fail("section " + std::string(name) + " is not closed");
    for (std::size_t i = pos_; i < at; ++i) line_ += data_[i] == '\n';
    pos_ = at + end.size();
  }

 private:
  void skip_space() {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) {
      if (data_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  std::string data_;
  std::string name_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  std::size_t token_line_ = 1;
};

int nodes_of_msh_type(int type) {
  switch (type) {
    case 15:
      return 1;
    case 1:
      return 2;
    case 8:  // line3: skipped like lines
      return 3;
    case 2:
      return 3;
    case 3:
      return 4;
    case 4:
      return 4;
    case 5:
      return 8;
    case 6:
      return 6;
    case 7:
      return 5;
    case 9:  // order 2: tri6, quad8, tet10, hex20, prism15, pyramid13
      return 6;
    case 16:
      return 8;
    case 11:
      return 10;
    case 17:
      return 20;
    case 18:
      return 15;
    case 19:
      return 13;
    default:
      return -1;
  }
}

// The order of a surface or volume element type (0 for points and lines).
int order_of_msh_type(int type) {
  switch (type) {
    case 2:
    case 3:
    case 4:
    case 5:
    case 6:
    case 7:
      return 1;
    case 9:
    case 16:
    case 11:
    case 17:
    case 18:
    case 19:
      return 2;
    default:
      return 0;
  }
}

struct Reader {
  Cursor& in;
  MixedMesh& mesh;
  bool binary = false;
  std::unordered_map<long, std::int32_t> node_index;
  std::map<std::pair<int, int>, int> entity_physical;  // (dim, tag) -> first physical tag

  std::int32_t node(long tag) {
    const auto it = node_index.find(tag);
    if (it == node_index.end()) in.fail("element refers to unknown node " + std::to_string(tag));
    return it->second;
  }

  // The physical group hexfem's writer puts the NC quad faces in (mesh_io.hpp): not boundary
  // faces; the NC flags are derived from the cells again.
  int nc_physical() const {
    for (const auto& [key, name] : mesh.physical_names)
      if (key.first == 2 && name == kNonconformalGroup) return key.second;
    return 0;
  }

  // 0 until the first surface or volume element; then its order, which every other must share.
  int order = 0;

  void add_element(int type, int elementary, int physical, const long* tags) {
    std::int32_t ids[kMaxElementNodes];
    const int n = nodes_of_msh_type(type);
    const bool face = type == 2 || type == 3 || type == 9 || type == 16;
    if (face && physical != 0 && physical == nc_physical()) return;
    if (n < 0)
      in.fail("element type " + std::to_string(type) +
              " is not supported (only points, lines, triangles, quads, tets, hexes, prisms, "
              "pyramids, of order 1 or 2)");
    const int element_order = order_of_msh_type(type);
    if (element_order == 0) return;  // points and lines carry nothing we keep
    if (order == 0) {
      order = element_order;
      mesh.order = order;
    } else if (element_order != order) {
      in.fail("the mesh mixes elements of order 1 and 2");
    }
    for (int i = 0; i < n; ++i) ids[i] = node(tags[i]);
    if (face) {
      const bool quad = type == 3 || type == 16;
      mesh.add_bface(ids[0], ids[1], ids[2], quad ? ids[3] : -1, elementary, physical);
      if (order == 2) {  // tri6 / quad8: corners, then the node of edge (v_i, v_i+1) at slot i
        const int nc = quad ? 4 : 3;
        for (int i = 0; i < 4; ++i) mesh.bface_edge_nodes.push_back(i < nc ? ids[nc + i] : -1);
      }
      return;
    }
    const CellKind kind = type == 4 || type == 11   ? CellKind::Tet4
                          : type == 5 || type == 17 ? CellKind::Hex8
                          : type == 6 || type == 18 ? CellKind::Wedge6
                                                    : CellKind::Pyramid5;
    mesh.add_cell(kind, ids, elementary, physical);
    if (order == 2) {  // corners, then the mid-edge nodes in Gmsh's (element_topology.hpp) order
      const int nc = num_nodes(kind), ne = num_edges(kind);
      for (int i = 0; i < kMaxCellEdges; ++i)
        mesh.cell_edge_nodes.push_back(i < ne ? ids[nc + i] : -1);
    }
  }

  void physical_names() {
    const long n = in.integer("number of physical names");
    for (long i = 0; i < n; ++i) {
      const int dim = static_cast<int>(in.integer("physical dimension"));
      const int tag = static_cast<int>(in.integer("physical tag"));
      std::string name = in.rest_of_line();
      const auto a = name.find('"'), b = name.rfind('"');
      if (a == std::string::npos || b == a) in.fail("physical name must be quoted");
      mesh.physical_names[{dim, tag}] = name.substr(a + 1, b - a - 1);
    }
    in.expect("$EndPhysicalNames");
  }

  // MSH 4.1 $Entities: remember each entity's first physical tag.
  void entities() {
    long count[4];
    if (binary) {
      in.skip_one_newline();
      for (long& c : count) c = static_cast<long>(in.binary<std::uint64_t>());
    } else {
      for (long& c : count) c = in.integer("entity count");
    }
    for (int dim = 0; dim < 4; ++dim) {
      for (long e = 0; e < count[dim]; ++e) {
        const int nbox = dim == 0 ? 3 : 6;
        int tag;
        long nphys;
        std::vector<int> phys;
        if (binary) {
          tag = in.binary<std::int32_t>();
          for (int i = 0; i < nbox; ++i) in.binary<double>();
          nphys = static_cast<long>(in.binary<std::uint64_t>());
          for (long i = 0; i < nphys; ++i) phys.push_back(in.binary<std::int32_t>());
          if (dim > 0) {
            const auto nb = in.binary<std::uint64_t>();
            for (std::uint64_t i = 0; i < nb; ++i) in.binary<std::int32_t>();
          }
        } else {
          tag = static_cast<int>(in.integer("entity tag"));
          for (int i = 0; i < nbox; ++i) in.real("bounding box coordinate");
          nphys = in.integer("number of physical tags");
          for (long i = 0; i < nphys; ++i)
            phys.push_back(static_cast<int>(in.integer("physical tag")));
          if (dim > 0) {
            const long nb = in.integer("number of bounding entities");
            for (long i = 0; i < nb; ++i) in.integer("bounding entity tag");
          }
        }
        if (nphys < 0 || nphys > 1000000) in.fail("bad number of physical tags");
        entity_physical[{dim, tag}] = phys.empty() ? 0 : phys.front();
      }
    }
    in.expect("$EndEntities");
  }

  // The first line of $Nodes / $Elements in 4.1: blocks, count, min tag, max tag.
  std::pair<std::uint64_t, std::uint64_t> section_header(const std::string& what) {
    std::uint64_t v[4];
    if (binary) in.skip_one_newline();
    const char* names[4] = {"blocks", "count", "min tag", "max tag"};
    for (int k = 0; k < 4; ++k)
      v[k] = binary ? in.binary<std::uint64_t>()
                    : static_cast<std::uint64_t>(in.integer((what + " " + names[k]).c_str()));
    return {v[0], v[1]};
  }

  void nodes41() {
    const auto [blocks, total] = section_header("node");
    if (total > (1ull << 31)) in.fail("too many nodes");
    mesh.nodes.reserve(total);
    node_index.reserve(total);
    std::vector<long> tags;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      int dim, parametric;
      std::uint64_t n;
      if (binary) {
        dim = in.binary<std::int32_t>();
        in.binary<std::int32_t>();
        parametric = in.binary<std::int32_t>();
        n = in.binary<std::uint64_t>();
      } else {
        dim = static_cast<int>(in.integer("entity dimension"));
        in.integer("entity tag");
        parametric = static_cast<int>(in.integer("parametric flag"));
        n = in.integer("number of nodes in block");
      }
      if (n > total) in.fail("node block larger than the node count");
      const int extra = parametric ? dim : 0;
      tags.resize(n);
      for (auto& t : tags)
        t = binary ? static_cast<long>(in.binary<std::uint64_t>()) : in.integer("node tag");
      for (std::uint64_t i = 0; i < n; ++i) {
        Vec3 x;
        for (double& c : x) c = binary ? in.binary<double>() : in.real("node coordinate");
        check_finite(x, tags[i]);
        for (int k = 0; k < extra; ++k)
          binary ? in.binary<double>() : in.real("parametric coordinate");
        if (!node_index.emplace(tags[i], static_cast<std::int32_t>(mesh.nodes.size())).second)
          in.fail("duplicate node tag " + std::to_string(tags[i]));
        mesh.nodes.push_back(x);
      }
    }
    if (mesh.nodes.size() != total) in.fail("node count does not match the header");
    in.expect("$EndNodes");
  }

  void elements41() {
    const auto [blocks, total] = section_header("element");
    std::uint64_t seen = 0;
    long tags[kMaxElementNodes + 1];
    for (std::uint64_t b = 0; b < blocks; ++b) {
      int dim, entity, type;
      std::uint64_t n;
      if (binary) {
        dim = in.binary<std::int32_t>();
        entity = in.binary<std::int32_t>();
        type = in.binary<std::int32_t>();
        n = in.binary<std::uint64_t>();
      } else {
        dim = static_cast<int>(in.integer("entity dimension"));
        entity = static_cast<int>(in.integer("entity tag"));
        type = static_cast<int>(in.integer("element type"));
        n = in.integer("number of elements in block");
      }
      const int nn = nodes_of_msh_type(type);
      if (nn < 0) add_element(type, 0, 0, tags);  // fails with the type's name
      if (n > total) in.fail("element block larger than the element count");
      const auto it = entity_physical.find({dim, entity});
      const int physical = it == entity_physical.end() ? 0 : it->second;
      for (std::uint64_t e = 0; e < n; ++e) {
        for (int i = 0; i <= nn; ++i)
          tags[i] = binary ? static_cast<long>(in.binary<std::uint64_t>())
                           : in.integer("element node tag");
        add_element(type, entity, physical, tags + 1);
      }
      seen += n;
    }
    if (seen != total) in.fail("element count does not match the header");
    in.expect("$EndElements");
  }

  // NaN and inf parse as numbers; a node there has no place in a mesh (issue 14 item 6).
  void check_finite(const Vec3& x, long tag) {
    for (double c : x)
      if (!std::isfinite(c))
        in.fail("node " + std::to_string(tag) + " has a coordinate that is not a finite number");
  }

  void nodes22() {
    const long n = in.integer("number of nodes");
    if (n < 0) in.fail("negative node count");
    for (long i = 0; i < n; ++i) {
      const long tag = in.integer("node tag");
      Vec3 x;
      for (double& c : x) c = in.real("node coordinate");
      check_finite(x, tag);
      if (!node_index.emplace(tag, static_cast<std::int32_t>(mesh.nodes.size())).second)
        in.fail("duplicate node tag " + std::to_string(tag));
      mesh.nodes.push_back(x);
    }
    in.expect("$EndNodes");
  }

  void elements22() {
    const long n = in.integer("number of elements");
    long tags[kMaxElementNodes + 1];
    for (long e = 0; e < n; ++e) {
      in.integer("element tag");
      const int type = static_cast<int>(in.integer("element type"));
      const long ntags = in.integer("number of element tags");
      if (ntags < 0 || ntags > 100) in.fail("bad number of element tags");
      long physical = 0, elementary = 0;
      for (long t = 0; t < ntags; ++t) {
        const long v = in.integer("element tag value");
        if (t == 0) physical = v;
        if (t == 1) elementary = v;
      }
      const int nn = nodes_of_msh_type(type);
      if (nn < 0) add_element(type, 0, 0, tags);
      for (int i = 0; i < nn; ++i) tags[i] = in.integer("element node tag");
      add_element(type, static_cast<int>(elementary), static_cast<int>(physical), tags);
    }
    in.expect("$EndElements");
  }
};

}  // namespace

MixedMesh read_msh(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error("cannot open '" + path.string() + "'");
  std::stringstream buffer;
  buffer << file.rdbuf();
  std::string data = buffer.str();
  if (data.empty()) throw Error("'" + path.string() + "' is empty");
  Cursor in(std::move(data), path.filename().string());

  if (in.token() != "$MeshFormat") in.fail("not a Gmsh MSH file (no $MeshFormat header)");
  const std::string_view version = in.token();
  const int file_type = static_cast<int>(in.integer("file type"));
  const int data_size = static_cast<int>(in.integer("data size"));
  MixedMesh mesh;
  Reader r{in, mesh, false, {}, {}};
  r.binary = file_type == 1;
  const bool v41 = version == "4.1";
  if (!v41 && !(version.substr(0, 2) == "2." && !r.binary))
    in.fail("MSH version " + std::string(version) + (r.binary ? " binary" : "") +
            " is not supported (MSH 4.1 ASCII/binary or 2.2 ASCII)");
  if (r.binary) {
    if (data_size != 8)
      in.fail("binary MSH with data size " + std::to_string(data_size) + " is not supported");
    in.skip_one_newline();
    if (in.binary<std::int32_t>() != 1)
      in.fail("binary MSH with foreign byte order is not supported");
  }
  in.expect("$EndMeshFormat");

  bool have_nodes = false;
  while (!in.at_end()) {
    const std::string_view section = in.token();
    if (section == "$PhysicalNames") {
      r.physical_names();
    } else if (section == "$Entities" && v41) {
      r.entities();
    } else if (section == "$Nodes") {
      v41 ? r.nodes41() : r.nodes22();
      have_nodes = true;
    } else if (section == "$Elements") {
      if (!have_nodes) in.fail("$Elements before $Nodes");
      v41 ? r.elements41() : r.elements22();
    } else if (section == "$HexfemLengthUnit") {
      const std::string_view unit = in.token();
      if (unit != "mm" && unit != "m")
        in.fail("length unit '" + std::string(unit.substr(0, 40)) + "' is not mm or m");
      mesh.length_unit = unit;
      in.expect("$EndHexfemLengthUnit");
    } else if (!section.empty() && section[0] == '$') {
      in.skip_section(section);
    } else {
      in.fail("unexpected '" + std::string(section.substr(0, 40)) + "' between sections");
    }
  }
  if (!have_nodes) in.fail("no $Nodes section");
  std::erase_if(mesh.physical_names, [](const auto& kv) {
    return kv.first.first == 2 && kv.second == kNonconformalGroup;
  });
  flag_nonconformal_quads(mesh);
  return mesh;
}

}  // namespace hexfem
