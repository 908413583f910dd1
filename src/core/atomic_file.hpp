#pragma once
// Every file the tools write goes through here, so that a reader never meets a short or mixed file:
// the bytes go to a temporary of this process's own beside the target (".NAME.rtrtmp-PID-XXXXXX", created
// with O_EXCL), are fsynced, and only then renamed over the target (or linked, when an existing file must
// be kept), and the folder is fsynced. The temporary is removed on every error path, on SIGINT/SIGTERM,
// and — when a killed run left it — by the next write to the same target.
#include <filesystem>
#include <string_view>

namespace rtr {

enum class Replace { Yes, No };  // No: an existing target is kept and OutputExists is thrown

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);  // creates the temporary; throws rtr::Error naming target
  ~AtomicFile();                                      // removes the temporary unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  int fd() const { return fd_; }
  void write(const void* data, size_t size);            // all of it, or throws
  void writeFrom(const std::filesystem::path& source);  // a regular file's bytes (core/input_file), or throws
  // fsync and close: the bytes are safely on disk under the temporary's name (a full disk has shown by
  // now), to be put in place by commit() later — how several files become one unit (rtr-bake's scene and
  // its textures).
  void sync();
  // Makes the bytes the target's (after sync(), unless done). With Replace::No, fails with OutputExists if the target exists by then
  // (checked by the kernel, so of two writers exactly one wins).
  void commit(Replace replace = Replace::Yes);
  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temporary() const { return tmp_; }

 private:
  std::filesystem::path target_, tmp_;
  int fd_ = -1;
  int slot_ = -1;  // in the signal handler's registry
};

void writeFileAtomic(const std::filesystem::path& file, std::string_view bytes, Replace replace = Replace::Yes);
void copyFileAtomic(const std::filesystem::path& from, const std::filesystem::path& to, Replace replace);

// Removes temporaries of `target` whose process is gone (what a SIGKILL leaves); returns how many.
size_t removeStaleTemporaries(const std::filesystem::path& target);

}  // namespace rtr
