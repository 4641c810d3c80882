#include "input/sdl/sdl_backend.hpp"

#include <SDL.h>

#include "input/evdev/evdev_pad.hpp"

namespace marionette::input {

SdlBackend::~SdlBackend() { stop(); }

Outcome SdlBackend::start(const std::string& mapping_file) {
    SDL_SetHint(SDL_HINT_NO_SIGNAL_HANDLERS, "1");
    SDL_SetHint(SDL_HINT_JOYSTICK_ALLOW_BACKGROUND_EVENTS, "1");
    if (SDL_InitSubSystem(SDL_INIT_GAMECONTROLLER | SDL_INIT_EVENTS) != 0)
        return Outcome::failure(std::string("SDL2 cannot start its game controller subsystem: ") + SDL_GetError());
    started_ = true;
    if (!mapping_file.empty()) {
        mappings_ = SDL_GameControllerAddMappingsFromFile(mapping_file.c_str());
        if (mappings_ < 0) {
            Outcome unread = Outcome::failure(mapping_file + ": SDL2 cannot read the mapping file: " + SDL_GetError());
            stop();
            return unread;
        }
    }
    open_first();
    return Outcome::success();
}

void SdlBackend::stop() {
    if (controller_) SDL_GameControllerClose(controller_);
    controller_ = nullptr;
    if (started_) SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER | SDL_INIT_EVENTS);
    started_ = false;
}

int SdlBackend::joysticks() const { return started_ ? SDL_NumJoysticks() : 0; }

std::string SdlBackend::controller_name() const {
    const char* n = controller_ ? SDL_GameControllerName(controller_) : nullptr;
    return n ? n : "";
}

void SdlBackend::open_first() {
    if (controller_) return;
    for (int i = 0; i < SDL_NumJoysticks(); ++i) {
        if (!SDL_IsGameController(i)) continue;
        controller_ = SDL_GameControllerOpen(i);
        if (controller_) {
            instance_ = SDL_JoystickInstanceID(SDL_GameControllerGetJoystick(controller_));
            ++connects_;
            return;
        }
    }
}

void SdlBackend::fill(InputSample& s) const {
    const auto axis = [&](SDL_GameControllerAxis a) {
        const int v = SDL_GameControllerGetAxis(controller_, a);
        return normalise_centred(v, -32768, 32767);
    };
    s.t_ns = monotonic_now_ns();
    s.lx = axis(SDL_CONTROLLER_AXIS_LEFTX);
    s.ly = flip_axis(axis(SDL_CONTROLLER_AXIS_LEFTY));  // SDL's y grows downwards
    s.rx = axis(SDL_CONTROLLER_AXIS_RIGHTX);
    s.ry = flip_axis(axis(SDL_CONTROLLER_AXIS_RIGHTY));
    s.lt = normalise_trigger(SDL_GameControllerGetAxis(controller_, SDL_CONTROLLER_AXIS_TRIGGERLEFT), 0, 32767);
    s.rt = normalise_trigger(SDL_GameControllerGetAxis(controller_, SDL_CONTROLLER_AXIS_TRIGGERRIGHT), 0, 32767);
    // SDL's buttons are positional too (A = south); map by name to our order.
    struct Map { SDL_GameControllerButton sdl; Button ours; };
    static constexpr Map kMap[] = {
        {SDL_CONTROLLER_BUTTON_A, Button::south}, {SDL_CONTROLLER_BUTTON_B, Button::east},
        {SDL_CONTROLLER_BUTTON_X, Button::west}, {SDL_CONTROLLER_BUTTON_Y, Button::north},
        {SDL_CONTROLLER_BUTTON_LEFTSHOULDER, Button::left_shoulder},
        {SDL_CONTROLLER_BUTTON_RIGHTSHOULDER, Button::right_shoulder},
        {SDL_CONTROLLER_BUTTON_BACK, Button::back}, {SDL_CONTROLLER_BUTTON_START, Button::start},
        {SDL_CONTROLLER_BUTTON_GUIDE, Button::guide}, {SDL_CONTROLLER_BUTTON_LEFTSTICK, Button::left_stick},
        {SDL_CONTROLLER_BUTTON_RIGHTSTICK, Button::right_stick}, {SDL_CONTROLLER_BUTTON_DPAD_UP, Button::dpad_up},
        {SDL_CONTROLLER_BUTTON_DPAD_DOWN, Button::dpad_down}, {SDL_CONTROLLER_BUTTON_DPAD_LEFT, Button::dpad_left},
        {SDL_CONTROLLER_BUTTON_DPAD_RIGHT, Button::dpad_right},
    };
    std::uint32_t b = 0;
    for (const Map& m : kMap)
        if (SDL_GameControllerGetButton(controller_, m.sdl)) b |= button_bit(m.ours);
    s.buttons = b;
    s.device_id = static_cast<std::uint32_t>(instance_);
    s.has_device_counter = false;
}

int SdlBackend::poll(std::span<InputSample> out, int timeout_ms) {
    if (!started_ || out.empty()) return 0;
    bool changed = false;
    SDL_Event e;
    if (SDL_WaitEventTimeout(&e, timeout_ms)) {
        do {
            switch (e.type) {
                case SDL_CONTROLLERDEVICEADDED: open_first(); break;
                case SDL_CONTROLLERDEVICEREMOVED:
                    if (controller_ && e.cdevice.which == instance_) {
                        SDL_GameControllerClose(controller_);
                        controller_ = nullptr;
                        ++disconnects_;
                        open_first();
                    }
                    break;
                case SDL_CONTROLLERAXISMOTION:
                case SDL_CONTROLLERBUTTONDOWN:
                case SDL_CONTROLLERBUTTONUP: changed = true; break;
                default: break;
            }
        } while (SDL_PollEvent(&e));
    }
    if (!changed || !controller_) return 0;
    fill(out[0]);
    return 1;
}

}  // namespace marionette::input
