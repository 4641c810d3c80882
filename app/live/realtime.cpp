#include "app/live/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cstring>
#include <string>

namespace marionette {

Outcome apply_thread_settings(std::thread& thread, const char* name, int priority, int cpu) {
    // A thread that was never started (no script input thread when a device
    // backend reads the pad) has no pthread: naming handle 0 would crash.
    if (!thread.joinable()) return Outcome::success();
    const pthread_t handle = thread.native_handle();
    pthread_setname_np(handle, name);  // best effort: only for tools like top and gdb
    std::string failed;
    if (priority > 0) {
        sched_param param{};
        param.sched_priority = priority;
        if (const int rc = pthread_setschedparam(handle, SCHED_FIFO, &param); rc != 0)
            failed += std::string(name) + " thread SCHED_FIFO " + std::to_string(priority) + ": " + std::strerror(rc);
    }
    if (cpu >= 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(static_cast<unsigned>(cpu), &set);
        if (const int rc = pthread_setaffinity_np(handle, sizeof set, &set); rc != 0)
            failed += (failed.empty() ? "" : "; ") + std::string(name) + " thread on CPU " + std::to_string(cpu) +
                      ": " + std::strerror(rc);
    }
    return failed.empty() ? Outcome::success() : Outcome::failure(failed);
}

Outcome lock_all_memory() {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) return Outcome::failure(std::string("mlockall: ") + std::strerror(errno));
    return Outcome::success();
}

}  // namespace marionette
