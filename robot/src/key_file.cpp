#include "arbci/robot/key_file.h"

#include <fcntl.h>
#include <openssl/rand.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <set>
#include <string>

namespace arbci::robot {

Key generateKey() {
  Key key{};
  if (RAND_bytes(key.data(), static_cast<int>(key.size())) != 1)
    throw KeyError("the system's random generator failed");
  return key;
}

void saveKey(const std::filesystem::path& path, const Key& key) {
  static const char* kHex = "0123456789abcdef";
  std::string text;
  for (std::uint8_t b : key) {
    text.push_back(kHex[b >> 4]);
    text.push_back(kHex[b & 15]);
  }
  text.push_back('\n');
  std::error_code ignored;
  std::filesystem::remove(path, ignored);  // so the new file gets mode 0600 whatever the old had
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    throw KeyError(path.string() + ": cannot create the key file: " + std::strerror(errno));
  const ssize_t written = ::write(fd, text.data(), text.size());
  ::fchmod(fd, 0600);
  ::close(fd);
  if (written != static_cast<ssize_t>(text.size()))
    throw KeyError(path.string() + ": writing the key failed");
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
  std::string text(buffer, n > 0 ? static_cast<size_t>(n) : 0);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  if (text.size() != 64 || !std::all_of(text.begin(), text.end(), [](char c) {
        return std::isxdigit(static_cast<unsigned char>(c));
      })) {
    throw KeyError(path.string() +
                   ": not a key (expected exactly 64 hex characters and a newline, nothing else)");
  }
  Key key{};
  for (size_t i = 0; i < key.size(); ++i)
    key[i] = static_cast<std::uint8_t>(std::stoi(text.substr(2 * i, 2), nullptr, 16));
  // 32 random bytes take about 31 distinct values; fewer than 12 means a made-up key (all zeros,
  // a repeated pattern), which anyone could guess.
  const std::set<std::uint8_t> distinct(key.begin(), key.end());
  if (distinct.size() < 12)
    throw KeyError(path.string() + ": the key does not look random (" +
                   std::to_string(distinct.size()) +
                   " distinct bytes of 32); make one with `arbci robot keygen --out FILE`");
  return key;
}

}  // namespace arbci::robot
