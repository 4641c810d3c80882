// Mesa's driver leaks a little from a module it unloads at eglTerminate, which
// LeakSanitizer can neither symbolize nor suppress (tests/CMakeLists.txt): leak
// checking is off in this program; AddressSanitizer's other checks are not.
extern "C" const char* __asan_default_options() { return "detect_leaks=0"; }
