// Checks every subcommand makes before it starts work, so bad paths and numbers fail at once
// with one line instead of after minutes of meshing (issue 14 items 4, 6, 7, 9).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace hexfem {

// An input file: it exists and is a regular file (a directory or a FIFO would hang or give a
// misleading message later). Throws hexfem::Error.
void check_input_file(const std::string& path);

// An output file named by `option` (e.g. "-o"): its extension is one of `extensions`
// (lower case, compared case-insensitively), it is not one of `inputs` (same file, also through
// links), it is not a directory and its folder exists and is writable. Throws hexfem::Error.
void check_output_file(const std::string& option, const std::string& path,
                       const std::vector<std::string>& extensions,
                       const std::vector<std::string>& inputs);

// Outputs given as a stem (converge -o STEM): the folder exists and is writable.
void check_output_folder(const std::string& option, const std::string& stem);

// `--binary` writes MSH 4.1 binary; for another format it would be silently ignored.
void check_binary_format(bool binary, const std::string& output);

// A number option the user gave: finite (NaN and inf parse as numbers). Throws hexfem::Error.
void check_finite(const std::string& option, double value);

// A mesh whose volume is off the CAD volume by more than `limit` (relative) is refused unless
// `force`: a size too large for the part gives a mesh that is not the part.
void check_mesh_volume(double mesh_volume, double cad_volume, double h, bool force,
                       double limit = 0.10);

// --size-at values, each "vertex:ID=S", "edge:ID=S" or "face:ID=S", S in mm or, written "0.5h", a
// fraction of the global size h (so one option serves every size of a convergence study). Appends
// (id, size) pairs; ids and sizes are checked against the part by the size field. Throws
// hexfem::Error on bad syntax.
void parse_size_at(const std::vector<std::string>& specs, double h,
                   std::vector<std::pair<int, double>>& vertex_sizes,
                   std::vector<std::pair<int, double>>& face_sizes,
                   std::vector<std::pair<int, double>>& edge_sizes);

// --glue's help, shared by `mesh`, `modal` and `converge`.
inline constexpr const char* kGlueHelp =
    "glue solids that touch or overlap into one bonded assembly (they then share faces; face ids "
    "as `hexfem info --glue` lists them)";

}  // namespace hexfem
