#include "core/atomic_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>

#include "core/error.hpp"
#include "core/input_file.hpp"

namespace rtr {
namespace {

// The signal handler's registry: fixed slots of plain chars, so the handler needs no allocation and never
// follows a pointer that another thread may be freeing.
constexpr int kSlots = 32;
constexpr size_t kPathMax = 4096;
char gPaths[kSlots][kPathMax];
std::atomic<bool> gLive[kSlots];
std::mutex gSlotMutex;  // taken only by registering threads, never by the handler

extern "C" void removeTemporariesAndDie(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (gLive[i].load(std::memory_order_acquire)) ::unlink(gPaths[i]);
  std::signal(sig, SIG_DFL);  // async-signal-safe; then die of the same signal, as the parent expects
  std::raise(sig);
}

void installHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      if (sigaction(sig, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) continue;  // keep the app's own
      struct sigaction sa {};
      sa.sa_handler = removeTemporariesAndDie;
      sigemptyset(&sa.sa_mask);
      sigaction(sig, &sa, nullptr);
    }
  });
}

int registerTemporary(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  installHandlers();
  std::lock_guard lock(gSlotMutex);
  for (int i = 0; i < kSlots; ++i)
    if (!gLive[i].load(std::memory_order_relaxed)) {
      std::memcpy(gPaths[i], path.c_str(), path.size() + 1);
      gLive[i].store(true, std::memory_order_release);
      return i;
    }
  return -1;  // more than kSlots writes at once: still removed on every error path, only not on a signal
}

void unregisterTemporary(int slot) {
  if (slot < 0) return;
  std::lock_guard lock(gSlotMutex);
  gLive[slot].store(false, std::memory_order_release);
}

// mkstemp makes 0600 files; outputs get what the user's umask gives any new file. Read once, before
// main, while there is one thread (umask can only be read by setting it).
const mode_t gFileMode = [] {
  const mode_t m = ::umask(022);
  ::umask(m);
  return mode_t(0666 & ~m);
}();

std::string tempPrefix(const std::filesystem::path& target) { return "." + target.filename().string() + ".rtrtmp-"; }

void fsyncFolder(const std::filesystem::path& dir) {
  const int d = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (d < 0) return;
  ::fsync(d);  // best effort: the rename is already visible; this makes it survive a power cut
  ::close(d);
}

std::string errnoText(int err) { return std::strerror(err); }

}  // namespace

size_t removeStaleTemporaries(const std::filesystem::path& target) {
  const std::filesystem::path dir = target.parent_path().empty() ? "." : target.parent_path();
  const std::string prefix = tempPrefix(target);
  DIR* d = ::opendir(dir.c_str());
  if (!d) return 0;
  size_t removed = 0;
  while (const dirent* e = ::readdir(d)) {
    const std::string_view name(e->d_name);
    if (!name.starts_with(prefix)) continue;
    char* end = nullptr;
    const long pid = std::strtol(e->d_name + prefix.size(), &end, 10);
    if (pid <= 0 || *end != '-') continue;                       // not one of ours
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // its writer may still be running
    if (::unlink((dir / e->d_name).c_str()) == 0) ++removed;
  }
  ::closedir(d);
  return removed;
}

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  removeStaleTemporaries(target_);
  const std::filesystem::path dir = target_.parent_path();
  std::string name = (dir.empty() ? std::filesystem::path(".") : dir) / tempPrefix(target_);
  name += std::to_string(::getpid()) + "-XXXXXX";
  fd_ = ::mkostemp(name.data(), O_CLOEXEC);
  if (fd_ < 0) throw fileError(target_.string(), "", "cannot create a temporary beside it: " + errnoText(errno));
  tmp_ = name;
  slot_ = registerTemporary(name);
  ::fchmod(fd_, gFileMode);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!tmp_.empty()) ::unlink(tmp_.c_str());
  unregisterTemporary(slot_);
}

void AtomicFile::write(const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd_, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw fileError(target_.string(), "", "cannot write: " + errnoText(n < 0 ? errno : EIO));
    p += n;
    size -= size_t(n);
  }
}

void AtomicFile::writeFrom(const std::filesystem::path& source) {
  InputFile in(source);
  char buf[1 << 16];
  for (size_t n; (n = in.read(buf, sizeof buf)) > 0;) write(buf, n);
}

void AtomicFile::sync() {
  if (fd_ < 0) return;
  if (::fsync(fd_) != 0) throw fileError(target_.string(), "", "cannot write: " + errnoText(errno));
  const int closed = ::close(fd_);
  fd_ = -1;
  if (closed != 0) throw fileError(target_.string(), "", "cannot write: " + errnoText(errno));
}

void AtomicFile::commit(Replace replace) {
  sync();
  if (replace == Replace::Yes) {
    if (::rename(tmp_.c_str(), target_.c_str()) != 0)
      throw fileError(target_.string(), "", "cannot rename the temporary into place: " + errnoText(errno));
  } else {
    // link() fails if the target exists, atomically: two writers cannot both think they created it.
    if (::link(tmp_.c_str(), target_.c_str()) != 0) {
      const int err = errno;
      if (err == EEXIST) throw OutputExists(target_.string() + ": exists; use --force to overwrite it");
      throw fileError(target_.string(), "", "cannot move the temporary into place: " + errnoText(err));
    }
    ::unlink(tmp_.c_str());
  }
  tmp_.clear();
  unregisterTemporary(slot_);
  slot_ = -1;
  fsyncFolder(target_.parent_path());
}

void writeFileAtomic(const std::filesystem::path& file, std::string_view bytes, Replace replace) {
  AtomicFile f(file);
  f.write(bytes.data(), bytes.size());
  f.commit(replace);
}

void copyFileAtomic(const std::filesystem::path& from, const std::filesystem::path& to, Replace replace) {
  AtomicFile f(to);
  f.writeFrom(from);
  f.commit(replace);
}

}  // namespace rtr
