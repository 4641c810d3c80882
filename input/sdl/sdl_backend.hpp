#pragma once
// The portable path: SDL2's GameController API (it does its own evdev/HIDAPI
// work and applies gamecontrollerdb mappings). One sample per poll in which any
// controller event arrived. Must be used from one thread (SDL's event queue).
#include <cstdint>
#include <span>
#include <string>

#include "input/input_sample.hpp"
#include "runtime/errors/outcome.hpp"

typedef struct _SDL_GameController SDL_GameController;

namespace marionette::input {

class SdlBackend {
public:
    SdlBackend() = default;
    ~SdlBackend();
    SdlBackend(const SdlBackend&) = delete;
    SdlBackend& operator=(const SdlBackend&) = delete;

    // Initialises SDL's game controller subsystem and loads the mapping file
    // (gamecontrollerdb.txt format) when one is named. Fails when SDL cannot
    // start or the file cannot be read.
    Outcome start(const std::string& mapping_file);
    // Waits up to timeout_ms; at most one sample per call (the open controller's state).
    int poll(std::span<InputSample> out, int timeout_ms);
    void stop();

    int joysticks() const;
    int mappings_loaded() const { return mappings_; }
    bool connected() const { return controller_ != nullptr; }
    std::string controller_name() const;
    std::uint64_t connects() const { return connects_; }
    std::uint64_t disconnects() const { return disconnects_; }

private:
    void open_first();
    void fill(InputSample& s) const;
    bool started_ = false;
    int mappings_ = 0;
    SDL_GameController* controller_ = nullptr;
    std::int32_t instance_ = -1;
    std::uint64_t connects_ = 0, disconnects_ = 0;
};

}  // namespace marionette::input
