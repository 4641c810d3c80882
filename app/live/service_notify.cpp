#include "app/live/service_notify.hpp"

#include <systemd/sd-daemon.h>

namespace marionette {

ServiceNotifier::ServiceNotifier() {
    std::uint64_t usec = 0;
    // > 0 when WATCHDOG_USEC is set and WATCHDOG_PID is unset or this process.
    if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) interval_ns_ = static_cast<std::int64_t>(usec) * 1000 / 2;
}

void ServiceNotifier::ready() {
    if (ready_sent_) return;
    ready_sent_ = true;
    sd_notify(0, "READY=1\nSTATUS=running");
}

void ServiceNotifier::poll(std::int64_t now_ns, std::uint64_t simulation_heartbeat, std::uint64_t render_heartbeat) {
    if (interval_ns_ <= 0 || !ready_sent_) return;
    if (next_check_ns_ == 0) {
        // The first look only takes the counters: progress is measured from here.
        next_check_ns_ = now_ns + interval_ns_;
        last_simulation_ = simulation_heartbeat;
        last_render_ = render_heartbeat;
        return;
    }
    if (now_ns < next_check_ns_) return;
    next_check_ns_ = now_ns + interval_ns_;
    const bool healthy = simulation_heartbeat != last_simulation_ && render_heartbeat != last_render_;
    last_simulation_ = simulation_heartbeat;
    last_render_ = render_heartbeat;
    if (!healthy) {
        ++withheld_;
        return;
    }
    ++pings_;
    sd_notify(0, "WATCHDOG=1");
}

void ServiceNotifier::stopping() {
    if (!ready_sent_ || stopping_sent_) return;
    stopping_sent_ = true;
    sd_notify(0, "STOPPING=1");
}

}  // namespace marionette
