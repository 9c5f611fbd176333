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

// From OpenSSL's CSPRNG, one that loadKey() accepts; throws KeyError if the generator fails.
Key generateKey();
// Writes the key with mode 0600 to a new regular file. An existing regular file is replaced only
// with `replace` (atomically, by rename); anything else there (a FIFO, a device, a link, a
// folder) is refused and left alone. Throws KeyError naming the file.
void saveKey(const std::filesystem::path& path, const Key& key, bool replace = false);
// Throws KeyError naming the file: missing, not a regular file, readable by others, not exactly
// 64 hex characters and one newline, or a key that could be guessed (fewer than 24 distinct
// bytes, all printable characters, a constant step).
Key loadKey(const std::filesystem::path& path);

}  // namespace arbci::robot
