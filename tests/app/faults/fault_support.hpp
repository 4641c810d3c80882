#pragma once
// Helpers for the fault-injection tests (docs/reliability.md, "Fault injection"):
// a private temporary folder, captured output, the process's resident memory,
// and the `marionette` program run as a child that a test can stop and resume.
#include <sys/types.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace marionette::test {

// A fresh folder under the temporary directory, removed by the destructor.
class TempFolder {
public:
    explicit TempFolder(const std::string& name);
    ~TempFolder();
    TempFolder(const TempFolder&) = delete;
    TempFolder& operator=(const TempFolder&) = delete;
    std::string path(const std::string& file) const { return folder_ + "/" + file; }
    const std::string& folder() const { return folder_; }

private:
    std::string folder_;
};

// Everything written to `f` so far.
std::string read_stream(std::FILE* f);
// Lines of `text` containing `needle`.
int count_lines_with(const std::string& text, const std::string& needle);
// This process's resident set size (/proc/self/statm), bytes.
std::int64_t resident_bytes();
// Writes `text` to `path` (replacing it); fails the calling test when it cannot.
void write_file(const std::string& path, const std::string& text);
std::string read_file_or_empty(const std::string& path);

// The value of "key": NUMBER in a flat JSON object (--stats-json); NaN when absent.
double json_number(const std::string& json, const std::string& key);

std::string marionette_program();

// `marionette ARGS...` (or another program) as a child, its stdout on a pipe the test reads line by
// line, stderr to a file; `env` entries ("NAME=value") are added to ours.
class Child {
public:
    Child(const std::vector<std::string>& args, const std::vector<std::string>& env, const std::string& stderr_file)
        : Child(marionette_program(), args, env, stderr_file) {}
    Child(const std::string& program, const std::vector<std::string>& args, const std::vector<std::string>& env,
          const std::string& stderr_file);
    ~Child();  // kills (SIGKILL) and reaps a child still running
    Child(const Child&) = delete;
    Child& operator=(const Child&) = delete;
    // Reads stdout until a line containing `needle` (true) or EOF / `timeout_s` (false).
    bool wait_for_line(const std::string& needle, double timeout_s);
    // Reads the rest of stdout and waits for the exit; the exit code, or
    // 128 + signal, or -1 when it outlives `timeout_s` (then it is killed).
    int finish(double timeout_s);
    pid_t pid() const { return pid_; }
    const std::string& output() const { return output_; }

private:
    pid_t pid_ = -1;
    int out_fd_ = -1;
    std::string output_;
    std::string pending_;  // the line being read
};


}  // namespace marionette::test
