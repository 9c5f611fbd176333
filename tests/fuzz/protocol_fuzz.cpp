// libFuzzer target for the robot protocol's decoder. Each input is decoded as it is (as an
// attacker would send it) and, with a valid MAC appended, as an authenticated message, so the
// payload parser is reached too. A decoded message must encode and decode to the same type.
#include <openssl/evp.h>
#include <openssl/hmac.h>

#include <cstdint>
#include <cstdlib>
#include <vector>

#include "arbci/robot/protocol.h"

using namespace arbci::robot;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, size_t size) {
  Key key{};
  key.fill(0x5a);
  (void)decode(data, size, key);

  std::vector<std::uint8_t> signed_input(data, data + size);
  unsigned char mac[32];
  unsigned int length = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), data, size, mac, &length);
  signed_input.insert(signed_input.end(), mac, mac + 32);
  const Decoded decoded = decode(signed_input.data(), signed_input.size(), key);
  if (decoded.ok()) {
    const auto again = encode(decoded.message, key);
    const Decoded round = decode(again.data(), again.size(), key);
    if (!round.ok() || round.message.type != decoded.message.type) std::abort();
  }
  return 0;
}
