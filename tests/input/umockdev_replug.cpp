// A umockdev test bed that unplugs a pad and plugs one back in while a command
// runs (tests/input/backends_run_tests.sh drives `marionette run` with it).
// Runs under umockdev-wrapper, so the command it starts inherits umockdev's
// preload and the test bed (UMOCKDEV_DIR). Timeline from start:
//   0 s         DESC is added, IOCTL answers ioctls on NODE, SCRIPT plays on NODE; COMMAND starts
//   UNPLUG_S    (SCRIPT must have played by then: umockdev 0.17 cannot wait for
//               it, and its runner aborts writing to a closed end) the node's
//               emulated device end is closed
//               (its reader gets a hang-up and EIO, as from a removed hidraw or
//               evdev node) and the device is removed (its node deleted, a
//               "remove" uevent sent)
//   REPLUG_S    DESC2 is added (the kernel's next node, NODE2), IOCTL answers on
//               NODE2 and SCRIPT2 plays there ("add" uevent)
// Exits with COMMAND's status (128 + signal when it was killed), 3 on a bad test bed.
// Usage: umockdev_replug DESC NODE IOCTL SCRIPT UNPLUG_S DESC2 NODE2 SCRIPT2 REPLUG_S -- COMMAND...
#include <umockdev.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace {

std::string read_file(const char* path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// The first "P: " line of a umockdev description: the device the node belongs to.
std::string first_syspath(const std::string& description) {
    const std::size_t at = description.find("P: ");
    if (at == std::string::npos) return {};
    const std::size_t end = description.find('\n', at);
    return "/sys" + description.substr(at + 3, end == std::string::npos ? std::string::npos : end - at - 3);
}

bool fail(const char* what, GError* error) {
    std::fprintf(stderr, "umockdev_replug: %s: %s\n", what, error ? error->message : "failed");
    return false;
}

bool plug(UMockdevTestbed* bed, const std::string& description, const char* node, const char* ioctl,
          const char* script) {
    GError* error = nullptr;
    if (!umockdev_testbed_add_from_string(bed, description.c_str(), &error)) return fail("add device", error);
    if (!umockdev_testbed_load_ioctl(bed, node, ioctl, &error)) return fail("load ioctl", error);
    if (!umockdev_testbed_load_script(bed, node, script, &error)) return fail("load script", error);
    return true;
}

void sleep_until(std::chrono::steady_clock::time_point start, double seconds) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(seconds)));
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 12 || std::strcmp(argv[10], "--") != 0) {
        std::fprintf(stderr,
                     "usage: umockdev_replug DESC NODE IOCTL SCRIPT UNPLUG_S DESC2 NODE2 SCRIPT2 REPLUG_S -- COMMAND...\n");
        return 3;
    }
    const std::string description = read_file(argv[1]);
    const char* node = argv[2];
    const char* ioctl = argv[3];
    const double unplug_s = std::atof(argv[5]);
    const std::string description2 = read_file(argv[6]);
    const char* node2 = argv[7];
    const double replug_s = std::atof(argv[9]);
    const std::string syspath = first_syspath(description);
    if (syspath == "/sys" || first_syspath(description2) == "/sys") {
        std::fprintf(stderr, "umockdev_replug: %s or %s has no device (P: line)\n", argv[1], argv[6]);
        return 3;
    }

    UMockdevTestbed* bed = umockdev_testbed_new();
    const auto start = std::chrono::steady_clock::now();
    if (!plug(bed, description, node, ioctl, argv[4])) return 3;
    // The command must not inherit the device end, or closing it here would not hang up.
    if (const int fd = umockdev_testbed_get_dev_fd(bed, node); fd >= 0) fcntl(fd, F_SETFD, FD_CLOEXEC);
    const pid_t child = fork();
    if (child < 0) return 3;
    if (child == 0) {
        execvp(argv[11], argv + 11);
        std::perror(argv[11]);
        _exit(127);
    }

    sleep_until(start, unplug_s);
    if (const int fd = umockdev_testbed_get_dev_fd(bed, node); fd >= 0) {
        // The test bed maps each pty to the device it emulates; the kernel will
        // reuse this pty's number for the next node, so its map entry goes too.
        std::string map = std::string(umockdev_testbed_get_root_dir(bed)) + "/dev/.ptymap/";
        for (const char* c = ptsname(fd); c && *c; ++c) map += *c == '/' ? '_' : *c;
        close(fd);
        unlink(map.c_str());
    }
    // umockdev 0.17's remove_device sends no uevent (later versions do): send
    // the kernel's "remove" first, while the device's properties are still there.
    umockdev_testbed_uevent(bed, syspath.c_str(), "remove");
    umockdev_testbed_remove_device(bed, syspath.c_str());
    std::fprintf(stderr, "umockdev_replug: %.2f s: %s unplugged\n",
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), node);

    sleep_until(start, replug_s);
    const bool plugged = plug(bed, description2, node2, ioctl, argv[8]);
    std::fprintf(stderr, "umockdev_replug: %.2f s: %s plugged in\n",
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), node2);
    int status = 0;
    waitpid(child, &status, 0);
    if (!plugged) return 3;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}
