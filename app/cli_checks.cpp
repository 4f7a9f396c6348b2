#include "app/cli_checks.hpp"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <regex>

#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace fs = std::filesystem;

void check_input_file(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw Error("no such file: '" + path + "'");
  if (fs::is_directory(st)) throw Error("'" + path + "' is a directory, not a file");
  if (!fs::is_regular_file(st))
    throw Error("'" + path + "' is not a regular file (a pipe or device cannot be read)");
}

namespace {

std::string folder_of(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

void check_folder(const std::string& option, const std::string& path) {
  const std::string dir = folder_of(path);
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw Error(option + " '" + path + "': '" + dir + "' is a file, not a folder");
  if (!fs::is_directory(dir, ec))
    throw Error(option + " '" + path + "': the folder '" + dir + "' does not exist");
  // A file made and removed there: permission bits say nothing to root, nor on a read-only
  // mount or /sys, where the write would fail only after the work.
  std::string probe = (fs::path(dir) / ".hexfem-probe-XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0)
    throw Error(option + " '" + path + "': the folder '" + dir + "' is not writable (" +
                std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::equivalent(a, b, ec)) return true;
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec) && !ec;
}

}  // namespace

void check_output_file(const std::string& option, const std::string& path,
                       const std::vector<std::string>& extensions,
                       const std::vector<std::string>& inputs) {
  const std::string ext = lower_extension(path);
  bool known = false;
  std::string list;
  for (std::size_t i = 0; i < extensions.size(); ++i) {
    known = known || extensions[i] == ext;
    list += (i == 0 ? "." : i + 1 == extensions.size() ? " or ." : ", .") + extensions[i];
  }
  for (const std::string& in : inputs)
    if (same_file(path, in))
      throw Error(option + " '" + path + "' is an input of this command; choose another name");
  if (!known) throw Error(option + " '" + path + "': the output must end in " + list);
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error(option + " '" + path + "' is a directory");
  check_folder(option, path);
  // A .vtu of a mesh with NC faces comes with <stem>_nc.vtu beside it: that one too must be
  // writable and no input, or the main file would be written and the companion fail after it.
  if (ext == "vtu") {
    fs::path nc = path;
    nc.replace_filename(nc.stem().string() + "_nc.vtu");
    for (const std::string& in : inputs)
      if (same_file(nc.string(), in))
        throw Error(option + " '" + path + "': its NC-face companion '" + nc.string() +
                    "' is an input of this command; choose another name");
    if (fs::is_directory(nc, ec))
      throw Error(option + " '" + path + "': its NC-face companion '" + nc.string() +
                  "' is a directory");
  }
}

void check_output_folder(const std::string& option, const std::string& stem) {
  check_folder(option, stem);
}

void check_binary_format(bool binary, const std::string& output) {
  if (binary && lower_extension(output) != "msh")
    throw Error("--binary is for .msh output only (got '" + output + "')");
}

void check_finite(const std::string& option, double value) {
  if (!std::isfinite(value))
    throw Error(option + " must be a finite number (got " + std::to_string(value) + ")");
}

void check_mesh_volume(double mesh_volume, double cad_volume, double h, bool force, double limit) {
  if (force || !(cad_volume > 0)) return;
  const double off = (mesh_volume - cad_volume) / cad_volume;
  if (std::abs(off) <= limit) return;
  char msg[400];
  std::snprintf(msg, sizeof msg,
                "the mesh volume is %+.1f %% off the CAD volume (%.6g vs %.6g mm^3): --h %g is "
                "too large for this part; use a smaller --h, or --force to accept it",
                100 * off, mesh_volume, cad_volume, h);
  throw Error(msg);
}

void parse_size_at(const std::vector<std::string>& specs, double h,
                   std::vector<std::pair<int, double>>& vertex_sizes,
                   std::vector<std::pair<int, double>>& face_sizes,
                   std::vector<std::pair<int, double>>& edge_sizes) {
  static const std::regex re(R"((vertex|edge|face):(\d+)=([-+0-9.eE]+)(h?))");
  for (const auto& s : specs) {
    std::smatch m;
    const std::string expected =
        "--size-at '" + s +
        "': expected vertex:ID=S, edge:ID=S or face:ID=S (S in mm, or like 0.5h)";
    if (!std::regex_match(s, m, re)) throw Error(expected);
    int id = 0;
    double size = 0;
    try {
      id = std::stoi(m[2].str());
      size = std::stod(m[3].str());
    } catch (const std::exception&) {
      throw Error(expected);
    }
    if (m[4].length() > 0) size *= h;
    const std::string kind = m[1].str();
    (kind == "vertex" ? vertex_sizes
     : kind == "edge" ? edge_sizes
                      : face_sizes)
        .emplace_back(id, size);
  }
}

}  // namespace hexfem
