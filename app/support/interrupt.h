// Ctrl+C and SIGTERM end a session like its own stop does: the session ends at the next frame and
// saves its summary (the recording is safe on disk record by record either way).
#pragma once

namespace arbci::app {

// Installs the handlers (SIGINT, SIGTERM); call once before the session loop.
void watchInterrupts();
bool interruptRequested();

}  // namespace arbci::app
