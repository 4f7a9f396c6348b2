#include "mesher/mesh/atomic_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>

#include "mesher/mesh/error.hpp"

namespace hexfem {

void write_atomically(const std::filesystem::path& path, bool binary,
                      const std::function<void(std::ostream&)>& write) {
  const std::filesystem::path tmp =
      path.string() + ".tmp." + std::to_string(static_cast<long>(::getpid()));
  try {
    {
      std::ofstream out(tmp, binary ? std::ios::binary | std::ios::out : std::ios::out);
      if (!out) throw Error("cannot write '" + path.string() + "'");
      write(out);
      out.flush();
      if (!out) throw Error("write failed for '" + path.string() + "' (disk full?)");
    }
    std::filesystem::rename(tmp, path);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace hexfem
