// The pipeline's steady state allocates nothing: this program replaces the global
// operator new/delete (and, outside sanitizer builds, malloc & co. through
// glibc's __libc_* entry points) with counting versions, then drives the same
// per-sample, per-tick and per-frame code the threads run (InputRingWriter,
// SimulationLoop, FrameLoop) for 10 000 ticks and 1 000 frames after warm-up.
// It is its own executable because the replacement is process-wide.
#include <catch2/catch.hpp>

#include <pthread.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "app/config/config.hpp"
#include "app/live/pipeline.hpp"
#include "app/config/program_source.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::uint64_t> g_allocations{0};
// While set, only allocations made by threads other than this one are counted
// (the pipeline's workers, while the test's thread is the writer).
std::atomic<bool> g_workers_only{false};
std::atomic<pthread_t> g_writer_thread{};
void note_allocation() {
    if (!g_counting.load(std::memory_order_relaxed)) return;
    if (g_workers_only.load(std::memory_order_relaxed) && pthread_equal(pthread_self(), g_writer_thread.load())) return;
    g_allocations.fetch_add(1, std::memory_order_relaxed);
}
void* allocate(std::size_t n, std::size_t align) {
    note_allocation();
    if (n == 0) n = 1;
    void* p = nullptr;
    if (align <= alignof(std::max_align_t)) p = std::malloc(n);
    else if (posix_memalign(&p, align, n) != 0) p = nullptr;
    if (!p) throw std::bad_alloc();
    return p;
}
}  // namespace

void* operator new(std::size_t n) { return allocate(n, 0); }
void* operator new[](std::size_t n) { return allocate(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) { return allocate(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return allocate(n, static_cast<std::size_t>(a)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
    try { return allocate(n, 0); } catch (...) { return nullptr; }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
    try { return allocate(n, 0); } catch (...) { return nullptr; }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
// The C allocator too (a sanitizer owns malloc, so only in plain builds).
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void* malloc(std::size_t n) noexcept {
    note_allocation();
    return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
    note_allocation();
    return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) noexcept {
    note_allocation();
    return __libc_realloc(p, n);
}
void* memalign(std::size_t align, std::size_t n) noexcept {
    note_allocation();
    return __libc_memalign(align, n);
}
void* aligned_alloc(std::size_t align, std::size_t n) noexcept {
    note_allocation();
    return __libc_memalign(align, n);
}
int posix_memalign(void** out, std::size_t align, std::size_t n) noexcept {
    note_allocation();
    *out = __libc_memalign(align, n);
    return *out ? 0 : 12;  // ENOMEM
}
}
#endif

using namespace marionette;

TEST_CASE("the counting allocator sees allocations", "[zero_alloc]") {
    g_allocations = 0;
    g_counting = true;
    auto* p = new std::vector<int>(100);
    void* q = std::malloc(64);
    g_counting = false;
    delete p;
    std::free(q);
    CHECK(g_allocations.load() >= 2);  // both the vector and its buffer, or malloc too
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
    g_allocations = 0;
    g_counting = true;
    void* r = std::malloc(32);  // the C allocator alone is seen too
    g_counting = false;
    std::free(r);
    CHECK(g_allocations.load() == 1);
#endif
}

TEST_CASE("10 000 ticks and 1 000 frames after warm-up allocate nothing", "[zero_alloc]") {
    const SimConfig config = default_config().sim;
    SimConfig retuned = config;
    retuned.max_speed = 2.0f;
    // Everything that allocates happens before the counted part, as in run_pipeline.
    const std::vector<TickInput> samples = render_stick_program(load_program("builtin:demo"), kSimulatedControllerHz);
    auto shared = std::make_unique<PipelineShared>();
    SimulationLoop loop(config, *shared);
    FrameLoop frames(*shared);
    InputRingWriter<InputRing> writer(shared->input_ring);
    const std::int64_t tick_ns = 1'000'000'000 / config.tick_rate_hz;
    const std::int64_t sample_ns = 1'000'000'000 / kSimulatedControllerHz;

    std::int64_t next_sample = 0;
    size_t sample_index = 0;
    std::uint64_t records = 0;
    TickRecord record;
    vec3 sink(0.0f);
    auto run = [&](int ticks, int frame_every) {
        for (int i = 0; i < ticks; ++i) {
            const std::int64_t t = static_cast<std::int64_t>(loop.simulation().state().tick + 1) * tick_ns;
            // The input thread's work: the samples read since the last tick.
            for (; next_sample <= t; next_sample += sample_ns) {
                TimedInput s;
                s.timestamp_ns = next_sample;
                s.input = samples[sample_index++ % samples.size()];
                if (sample_index % 3000 == 0) writer.push_disconnect(next_sample);  // hot-plug on the way
                else writer.push(s);
            }
            loop.run_tick(t, t + 100'000);
            while (shared->records.try_pop(record)) ++records;  // the writer's side, drained
            if (frame_every > 0 && i % frame_every == 0) sink += frames.run_frame(t + tick_ns / 2);
        }
    };
    run(480, 4);  // warm-up: two simulated seconds

    ConfigUpdate& update = shared->config_updates.back();  // live tuning, handed over before counting
    update.version = 1;
    update.config = retuned;
    shared->config_updates.publish();

    g_allocations = 0;
    g_counting = true;
    run(10'000, 10);  // 10 000 ticks, 1 000 frames, ~41 700 samples, one config change, hot-plugs
    g_counting = false;
    CHECK(g_allocations.load() == 0);
    CHECK(loop.simulation().state().tick == 10'480);
    CHECK(loop.config_changes() == 1);
    CHECK(loop.simulation().config().max_speed == 2.0f);
    CHECK(loop.assembler().disconnects() > 0);
    CHECK(records == 10'480 + 1);
    CHECK(frames.has_state());
    CHECK(writer.dropped() == 0);
    CHECK(std::isfinite(sink.x));
}

TEST_CASE("the pipeline's input, simulation and render threads allocate nothing in a whole run", "[zero_alloc]") {
    // The real threads of run_pipeline, from their start to their end; the
    // writer (this thread) may allocate (it formats text and writes files).
    for (const bool virtual_time : {true, false}) {
        INFO((virtual_time ? "virtual time" : "real time"));
        PipelineOptions o;
        o.config = default_config().sim;
        o.script = script_from_program(load_program("builtin:walk_stop"), kSimulatedControllerHz, {{0.5, 0.25}});
        o.total_ticks = virtual_time ? 1620 : 240;  // the whole program, or one real second
        o.virtual_time = virtual_time;
        o.status_lines = false;
        std::FILE* out = std::tmpfile();
        o.out = out;
        g_writer_thread = pthread_self();
        g_allocations = 0;
        g_workers_only = true;
        g_counting = true;
        const PipelineResult r = run_pipeline(o);
        g_counting = false;
        g_workers_only = false;
        std::fclose(out);
        CHECK(g_allocations.load() == 0);
        CHECK(r.ticks == o.total_ticks);
        CHECK(r.frames > 0);
        CHECK(r.disconnects == 1);
    }
}
