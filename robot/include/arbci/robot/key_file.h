// The shared key: 32 random bytes, kept as 64 hex characters in a file only its owner can read.
#pragma once

#include <filesystem>
#include <stdexcept>

#include "arbci/robot/protocol.h"

namespace arbci::robot {

class KeyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

Key generateKey();  // from OpenSSL's CSPRNG; throws KeyError if it fails
// Writes the key with mode 0600 (replacing any file). Throws KeyError naming the file.
void saveKey(const std::filesystem::path& path, const Key& key);
// Throws KeyError naming the file: missing, readable by others, or not 64 hex characters.
Key loadKey(const std::filesystem::path& path);

}  // namespace arbci::robot
