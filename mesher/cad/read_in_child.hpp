// Runs a CAD translator in a forked child, so that a crash inside OpenCASCADE on a damaged file
// is a one-line error instead of the end of hexfem.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "mesher/cad/cad_impl.hpp"

namespace hexfem {

// 'path', for messages.
std::string quoted(const std::filesystem::path& path);

// Reads the file in this process: the shape, and the unit scale, unit name and warnings in `m`.
using ReadHere = std::function<TopoDS_Shape(CadModel::Impl& m)>;

// kShapeBack: the child's shape comes back as binary BREP (IGES: the same meshes as an
// in-process read). kProbe: the child only tries the read, which is then done again here, for
// formats whose shape does not come back bit for bit the same through BREP (STEP: the same
// geometry, but surface meshes that differ at 1e-14 mm; the cost is a second read).
enum class ChildRead { kShapeBack, kProbe };

// `read_here` in a child; its shape (kShapeBack; else the same read again here), unit scale,
// unit name and warnings come into `m`. Its hexfem::Error comes back as it was; a crash is
// "'path' is not a readable FORMAT file (OpenCASCADE's reader crashed on it)".
TopoDS_Shape read_in_child(const std::filesystem::path& path, const std::string& format,
                           const ReadHere& read_here, CadModel::Impl& m,
                           ChildRead mode = ChildRead::kShapeBack);

}  // namespace hexfem
