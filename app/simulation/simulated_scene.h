// The simulated world as the session's "simulated" camera source: rendered with GL in the
// context current when the session steps (the application's), so it lives in the application.
#pragma once

namespace arbci::app {

// Adds "simulated" to session::sceneSources() (once; later calls do nothing).
void registerSimulatedScene();

}  // namespace arbci::app
