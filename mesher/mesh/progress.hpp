// Progress lines on stderr, only when stderr is a terminal (never in pipes, tests or --json).
#pragma once

#include <string>

namespace hexfem {

bool stderr_is_terminal();
// Overwrites the current stderr line with `message` (a no-op when stderr is not a terminal).
void show_progress(const std::string& message);
// Ends a progress line so the next output starts on a fresh line.
void end_progress();

}  // namespace hexfem
