#pragma once
// Optional real-time settings for the pipeline's threads ([realtime] in the
// configuration): SCHED_FIFO priority, CPU affinity, mlockall. Each fails
// saying what was refused, so the caller prints a single warning and the run
// carries on with normal scheduling.
#include <thread>

#include "runtime/errors/outcome.hpp"

namespace marionette {

// priority 0 and cpu −1 leave the thread as it is.
Outcome apply_thread_settings(std::thread& thread, const char* name, int priority, int cpu);
// Locks current and future pages in memory.
Outcome lock_all_memory();

}  // namespace marionette
