// A status line on stderr that rewrites itself ("\r..."): whoever writes one says so, so that an
// error printed meanwhile starts on a line of its own instead of over it.
#pragma once

namespace arbci::app {

void setStatusLineOpen(bool open);
bool statusLineOpen();

}  // namespace arbci::app
