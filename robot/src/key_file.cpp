#include "arbci/robot/key_file.h"

#include <fcntl.h>
#include <openssl/rand.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
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
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0)
    throw KeyError(path.string() + ": no key file (make one with `arbci robot keygen --out FILE`)");
  if (info.st_mode & (S_IRWXG | S_IRWXO)) {
    throw KeyError(path.string() +
                   ": the key file is accessible by others; make it private with chmod 600");
  }
  std::ifstream in(path);
  std::string text;
  in >> text;
  if (text.size() != 64 || !std::all_of(text.begin(), text.end(), [](char c) {
        return std::isxdigit(static_cast<unsigned char>(c));
      })) {
    throw KeyError(path.string() + ": not a key (expected 64 hex characters)");
  }
  Key key{};
  for (size_t i = 0; i < key.size(); ++i)
    key[i] = static_cast<std::uint8_t>(std::stoi(text.substr(2 * i, 2), nullptr, 16));
  return key;
}

}  // namespace arbci::robot
