#include "arbci/robot/key_file.h"

#include <fcntl.h>
#include <openssl/rand.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>
#include <set>
#include <string>

namespace arbci::robot {

namespace {

// Why a key could have been guessed, or nothing. 32 random bytes take about 30 distinct values
// (fewer than 24 happens to 1 key in 76,000, and generateKey() draws again); all-printable bytes
// are a passphrase typed as hex (1 in 6e13 by chance); a constant step is a counter (00 01 02 ..).
std::optional<std::string> weakness(const Key& key) {
  const std::set<std::uint8_t> distinct(key.begin(), key.end());
  if (distinct.size() < 24)
    return std::to_string(distinct.size()) + " distinct bytes of 32 (a repeated pattern)";
  if (std::all_of(key.begin(), key.end(), [](std::uint8_t b) { return b >= 0x20 && b < 0x7f; }))
    return std::string("every byte is a printable character (a passphrase, not random bytes)");
  const auto step = static_cast<std::uint8_t>(key[1] - key[0]);
  bool constant_step = true;
  for (size_t i = 2; i < key.size() && constant_step; ++i)
    constant_step = static_cast<std::uint8_t>(key[i] - key[i - 1]) == step;
  if (constant_step) return std::string("the bytes count up by a constant step");
  return std::nullopt;
}

// Writes all of `text` to `fd`; false on any failure.
bool writeAll(int fd, const std::string& text) {
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return ::fsync(fd) == 0;
}

std::string hexOf(const Key& key) {
  static const char* kHex = "0123456789abcdef";
  std::string text;
  for (std::uint8_t b : key) {
    text.push_back(kHex[b >> 4]);
    text.push_back(kHex[b & 15]);
  }
  text.push_back('\n');
  return text;
}

// Creates `path` (which must not exist: never follows a link) with mode 0600 and the key in it;
// removes it again if the write fails, since this call made it.
void createKeyFile(const std::filesystem::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0)
    throw KeyError(path.string() + ": cannot create the key file: " + std::strerror(errno));
  const bool written = ::fchmod(fd, 0600) == 0 && writeAll(fd, text);
  const int saved = errno;
  ::close(fd);
  if (!written) {
    ::unlink(path.c_str());
    throw KeyError(path.string() + ": writing the key failed: " + std::strerror(saved));
  }
}

}  // namespace

Key generateKey() {
  for (;;) {
    Key key{};
    if (RAND_bytes(key.data(), static_cast<int>(key.size())) != 1)
      throw KeyError("the system's random generator failed");
    if (!weakness(key)) return key;  // 1 draw in 76,000 is drawn again
  }
}

void saveKey(const std::filesystem::path& path, const Key& key, bool replace) {
  const std::string text = hexOf(key);
  struct stat info {};
  if (::lstat(path.c_str(), &info) != 0) {
    if (errno != ENOENT)
      throw KeyError(path.string() + ": cannot look at the path: " + std::strerror(errno));
    createKeyFile(path, text);
    return;
  }
  // Only ever a regular file is replaced: a FIFO would hang the writer, and replacing a device
  // node or a link's target would destroy something that is not a key.
  if (!S_ISREG(info.st_mode))
    throw KeyError(path.string() +
                   ": exists and is not a regular file (a FIFO, a device, a link or a folder); "
                   "a key is written only to a new regular file");
  if (!replace)
    throw KeyError(path.string() +
                   ": a file is already there; a key is never replaced silently (--force "
                   "replaces it, and every backend and client must then get the new one)");
  // The new key in a file of its own first, then renamed over the old: never half a key.
  const std::filesystem::path fresh = path.string() + ".new-" + std::to_string(::getpid());
  createKeyFile(fresh, text);
  if (::rename(fresh.c_str(), path.c_str()) != 0) {
    const int saved = errno;
    ::unlink(fresh.c_str());
    throw KeyError(path.string() + ": cannot replace the key file: " + std::strerror(saved));
  }
}

Key loadKey(const std::filesystem::path& path) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; only a regular file is read.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    if (errno == ENOENT)
      throw KeyError(path.string() +
                     ": no key file (make one with `arbci robot keygen --out FILE`)");
    throw KeyError(path.string() + ": cannot open the key file: " + std::strerror(errno));
  }
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd);
    throw KeyError(path.string() +
                   ": not a regular file (a key file is written by `arbci robot keygen`)");
  }
  if (info.st_mode & (S_IRWXG | S_IRWXO)) {
    ::close(fd);
    throw KeyError(path.string() +
                   ": the key file is accessible by others; make it private with chmod 600");
  }
  // A key file is 64 hex digits and a newline; read a little more to catch anything after.
  char buffer[256];
  const ssize_t n = ::read(fd, buffer, sizeof buffer);
  ::close(fd);
  const std::string text(buffer, n > 0 ? static_cast<size_t>(n) : 0);
  // Exactly as keygen writes it: a CR, a second newline or anything after the key is refused,
  // since a file that differs from the one written may not be the key the other side holds.
  const bool hex = text.size() == 65 && text.back() == '\n' &&
                   std::all_of(text.begin(), text.end() - 1,
                               [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
  if (!hex) {
    throw KeyError(path.string() +
                   ": not a key (expected exactly 64 hex characters and one newline, nothing "
                   "else; make one with `arbci robot keygen --out FILE`)");
  }
  Key key{};
  for (size_t i = 0; i < key.size(); ++i)
    key[i] = static_cast<std::uint8_t>(std::stoi(text.substr(2 * i, 2), nullptr, 16));
  if (const auto why = weakness(key))
    throw KeyError(path.string() + ": the key does not look random: " + *why +
                   "; make one with `arbci robot keygen --out FILE`");
  return key;
}

}  // namespace arbci::robot
