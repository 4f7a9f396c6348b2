// How much memory the machine can give this process now.
//
// Gives: MemAvailable of /proc/meminfo in bytes, 0 when unknown (not Linux, unreadable).
// Used where a run would otherwise be killed by the system half-way: the mesher's size check
// and the modal solver's choice of the direct or the iterative path.
#pragma once

namespace hexfem {

double available_memory_bytes();

}  // namespace hexfem
