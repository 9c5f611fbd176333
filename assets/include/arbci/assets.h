// Files under assets/ compiled into the binaries (shaders, the embedded default session), so the
// executables run from anywhere.
#pragma once

#include <string_view>

namespace arbci::assets {

// The text of an embedded file by its path under assets/, e.g. "shaders/flat.vert". Throws
// std::out_of_range for a name that was not embedded.
std::string_view embedded(std::string_view name);

}  // namespace arbci::assets
