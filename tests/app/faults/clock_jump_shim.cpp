// LD_PRELOAD shim for the clock-jump fault test (tests/app/faults/test_faults_process.cpp):
// every read of the realtime clock (clock_gettime(CLOCK_REALTIME*), gettimeofday,
// time) is shifted, cycling +6 hours, −1 year, +1 day, as a system clock set by
// hand or by NTP would jump. CLOCK_MONOTONIC is untouched. At exit it writes how
// many realtime reads it shifted to $MARIONETTE_CLOCK_JUMP_REPORT.
#include <dlfcn.h>
#include <sys/time.h>
#include <time.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace {
std::atomic<unsigned long> g_reads{0};

time_t next_offset() {
    static constexpr time_t kOffsets[] = {6 * 3600, -365 * 86400, 86400};
    return kOffsets[g_reads.fetch_add(1) % 3];
}

bool is_realtime(clockid_t id) {
    return id == CLOCK_REALTIME || id == CLOCK_REALTIME_COARSE || id == CLOCK_TAI;
}

struct Report {
    ~Report() {
        const char* path = std::getenv("MARIONETTE_CLOCK_JUMP_REPORT");
        if (!path) return;
        if (std::FILE* f = std::fopen(path, "w")) {
            std::fprintf(f, "realtime_reads %lu\n", g_reads.load());
            std::fclose(f);
        }
    }
} g_report;
}  // namespace

extern "C" {

int clock_gettime(clockid_t id, struct timespec* ts) {
    using Fn = int (*)(clockid_t, struct timespec*);
    static const Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "clock_gettime"));
    const int r = real(id, ts);
    if (r == 0 && ts && is_realtime(id)) ts->tv_sec += next_offset();
    return r;
}

int gettimeofday(struct timeval* tv, void* tz) {
    using Fn = int (*)(struct timeval*, void*);
    static const Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "gettimeofday"));
    const int r = real(tv, tz);
    if (r == 0 && tv) tv->tv_sec += next_offset();
    return r;
}

time_t time(time_t* out) {
    struct timespec ts {};
    clock_gettime(CLOCK_REALTIME, &ts);
    if (out) *out = ts.tv_sec;
    return ts.tv_sec;
}

}  // extern "C"
