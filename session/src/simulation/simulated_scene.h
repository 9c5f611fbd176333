// The simulated world as the session's "simulated" camera source (sceneSources()).
#pragma once

#include <memory>

#include "arbci/session/scene_source.h"

namespace arbci::session {

std::unique_ptr<SceneSource> makeSimulatedScene(const SceneSettings& settings);

}  // namespace arbci::session
