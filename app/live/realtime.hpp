#pragma once
// Optional real-time settings for the pipeline's threads ([realtime] in the
// configuration): SCHED_FIFO priority, CPU affinity, mlockall. Each returns ""
// on success or says what was refused, so the caller prints a single warning
// and the run carries on with normal scheduling.
#include <string>
#include <thread>

namespace marionette {

// priority 0 and cpu −1 leave the thread as it is.
std::string apply_thread_settings(std::thread& thread, const char* name, int priority, int cpu);
// Locks current and future pages in memory.
std::string lock_all_memory();

}  // namespace marionette
