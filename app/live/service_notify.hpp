#pragma once
// systemd's service notifications (sd_notify(3), docs/deploy.md "Watchdog"):
// READY=1 once the pipeline runs, then WATCHDOG=1 at half the unit's
// WatchdogSec= interval, but only while both the simulation and the render loop
// have made progress since the last look: a stuck loop stops the pings, and
// systemd restarts the service. Outside systemd (no NOTIFY_SOCKET) it does nothing.
#include <cstdint>

namespace marionette {

class ServiceNotifier {
public:
    // Reads NOTIFY_SOCKET and WATCHDOG_USEC/WATCHDOG_PID (sd_watchdog_enabled) once.
    ServiceNotifier();

    bool watchdog_enabled() const { return interval_ns_ > 0; }
    std::int64_t ping_interval_ns() const { return interval_ns_; }

    // The pipeline runs: READY=1 (once).
    void ready();
    // Called often by the writer thread with both loops' heartbeat counters: at
    // each interval, sends WATCHDOG=1 when both moved since the previous interval.
    void poll(std::int64_t now_ns, std::uint64_t simulation_heartbeat, std::uint64_t render_heartbeat);
    // STOPPING=1 when the run ends (once, after ready()).
    void stopping();

    std::uint64_t pings_sent() const { return pings_; }
    std::uint64_t pings_withheld() const { return withheld_; }

private:
    std::int64_t interval_ns_ = 0;  // half of WATCHDOG_USEC; 0: no watchdog
    std::int64_t next_check_ns_ = 0;
    std::uint64_t last_simulation_ = 0;
    std::uint64_t last_render_ = 0;
    bool ready_sent_ = false;
    bool stopping_sent_ = false;
    std::uint64_t pings_ = 0;
    std::uint64_t withheld_ = 0;
};

}  // namespace marionette
