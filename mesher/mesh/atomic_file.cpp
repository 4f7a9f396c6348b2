#include "mesher/mesh/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <mutex>
#include <random>
#include <streambuf>

#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

// The temporary files being written, for the signal handler: fixed storage, so removing them
// needs only async-signal-safe calls (unlink, raise).
constexpr int kSlots = 16;
constexpr std::size_t kPathMax = 4096;
std::array<std::array<char, kPathMax>, kSlots> g_temp_path;
std::array<std::atomic<bool>, kSlots> g_temp_used;  // the path is set: remove it on a signal
std::array<std::atomic<bool>, kSlots> g_busy;       // the slot belongs to a writer
std::once_flag g_handlers_installed;

extern "C" void remove_temp_files_and_die(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_temp_used[i].load()) ::unlink(g_temp_path[i].data());
  std::signal(sig, SIG_DFL);  // then die of the same signal, so the caller sees it
  std::raise(sig);
}

void install_handlers() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) continue;
    struct sigaction sa {};
    sa.sa_handler = remove_temp_files_and_die;
    sigemptyset(&sa.sa_mask);
    ::sigaction(sig, &sa, nullptr);
  }
}

// Holds a slot in the table while a temporary file may exist under its path.
class TempSlot {
 public:
  TempSlot() {
    std::call_once(g_handlers_installed, install_handlers);
    for (int i = 0; i < kSlots && slot_ < 0; ++i) {
      bool expected = false;
      if (g_busy[i].compare_exchange_strong(expected, true)) slot_ = i;
    }
    if (slot_ < 0) throw Error("too many files being written at once");
  }
  ~TempSlot() {
    clear();
    g_busy[slot_].store(false);
  }
  TempSlot(const TempSlot&) = delete;
  TempSlot& operator=(const TempSlot&) = delete;
  // Named before the file is created, so a signal right after creation still removes it.
  void set(const std::string& path) {
    clear();
    std::memcpy(g_temp_path[slot_].data(), path.c_str(), path.size() + 1);
    g_temp_used[slot_].store(true);
  }
  void clear() { g_temp_used[slot_].store(false); }

 private:
  int slot_ = -1;
};

// An output stream buffer over a file descriptor (std::ofstream cannot adopt one).
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd) { setp(buf_.data(), buf_.data() + buf_.size()); }
  bool failed() const { return failed_; }

 protected:
  int_type overflow(int_type c) override {
    if (!flush_buffer()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return flush_buffer() ? 0 : -1; }

 private:
  bool flush_buffer() {
    const char* p = pbase();
    while (!failed_ && p < pptr()) {
      const ssize_t n = ::write(fd_, p, static_cast<std::size_t>(pptr() - p));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0)
        failed_ = true;
      else
        p += n;
    }
    setp(buf_.data(), buf_.data() + buf_.size());
    return !failed_;
  }
  int fd_;
  bool failed_ = false;
  std::array<char, 1 << 16> buf_;
};

// Creates a new file next to `target` with a random short name; never follows a link, never
// opens an existing file. Returns the descriptor and leaves its name in `slot`.
int create_temp(const std::filesystem::path& target, TempSlot& slot, std::string& tmp) {
  const std::filesystem::path dir =
      target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  std::random_device rd;
  std::mt19937_64 rng((static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^ ::getpid());
  static const char kChars[] = "abcdefghijklmnopqrstuvwxyz0123456789";
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string name = ".hexfem-";
    for (int i = 0; i < 10; ++i) name += kChars[rng() % (sizeof kChars - 1)];
    tmp = (dir / (name + ".tmp")).string();
    if (tmp.size() >= kPathMax) throw Error("path too long: '" + target.string() + "'");
    slot.set(tmp);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) return fd;
    slot.clear();
    if (errno != EEXIST)
      throw Error("cannot write '" + target.string() + "': " + std::strerror(errno));
  }
  throw Error("cannot write '" + target.string() + "': no free temporary name");
}

}  // namespace

void write_atomically(const std::filesystem::path& path, bool /*binary*/,
                      const std::function<void(std::ostream&)>& write) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error("cannot write '" + path.string() + "': it is a directory");
  TempSlot slot;
  std::string tmp;
  const int fd = create_temp(path, slot, tmp);
  bool closed = false;
  try {
    FdBuf buf(fd);
    std::ostream out(&buf);
    write(out);
    out.flush();
    if (!out || buf.failed())
      throw Error("write failed for '" + path.string() + "': " + std::strerror(errno));
    closed = true;
    if (::close(fd) != 0)
      throw Error("write failed for '" + path.string() + "': " + std::strerror(errno));
    if (::rename(tmp.c_str(), path.c_str()) != 0)
      throw Error("cannot write '" + path.string() + "': " + std::strerror(errno));
  } catch (...) {
    if (!closed) ::close(fd);
    ::unlink(tmp.c_str());
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
