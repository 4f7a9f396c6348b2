// Writes that never leave a half-written file: write to "<path>.tmp.<pid>", then rename.
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace hexfem {

// Calls `write(stream)` on a temporary file next to `path` and renames it to `path` on success.
// On any failure the temporary file is removed and hexfem::Error is thrown.
void write_atomically(const std::filesystem::path& path, bool binary,
                      const std::function<void(std::ostream&)>& write);

// Lower-case extension without the dot ("msh", "vtu", "inp", ...).
std::string lower_extension(const std::filesystem::path& path);

}  // namespace hexfem
