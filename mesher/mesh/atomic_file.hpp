// Writes that never leave a half-written file: write to a temporary file in the same folder,
// then rename it over the target. The temporary file is created exclusively (O_EXCL, never
// through a symbolic link planted at its name), has a short name of its own (so a 255-byte
// output name still works), and is removed on SIGINT, SIGTERM and SIGHUP as well as on errors.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace hexfem {

// Calls `write(stream)` on a temporary file next to `path` and renames it to `path` on success.
// On any failure the temporary file is removed and hexfem::Error is thrown; `path` is then
// untouched. `binary` is kept for callers' clarity (the stream never translates line ends).
void write_atomically(const std::filesystem::path& path, bool binary,
                      const std::function<void(std::ostream&)>& write);

// Lower-case extension without the dot ("msh", "vtu", "inp", ...).
std::string lower_extension(const std::filesystem::path& path);

}  // namespace hexfem
