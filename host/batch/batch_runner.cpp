// batch_runner.cpp - `raster batch`: manifest frames, sharded, rendered by one worker per device (each
// through the library's raster::Session, as `raster render` renders) while I/O threads encode and write,
// with resume and a summary.
#include "batch/batch_runner.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <unordered_map>

#include <unistd.h>

#include <fmt/format.h>

#include "batch/outputs.h"
#include "batch/shard.h"
#include "api/api_internal.h"
#include "api/frame_files.h"
#include "base/warnings.h"
#include "batch/turntable.h"
#include "io/image_io.h"
#include "camera/camera.h"
#include "camera/orbit.h"

namespace sr {

Result<std::vector<BatchFrame>> expandJobs(const Manifest& manifest)
{
    std::vector<BatchFrame> frames;
    // Every file the batch reads (the manifest, the scene files) and writes (each frame's outputs and
    // sidecar), keyed by the resolved path, so that "a.png", "./a.png" and "link/a.png" are one file:
    // no file is written twice, and none that is read is written.
    std::map<std::string, std::string> inputs;  // resolved path -> what reads it
    inputs.emplace(resolvedPath(manifest.path), "the manifest");
    for (const ManifestJob& job : manifest.jobs)
        if (job.scene.compare(0, 7, "builtin") != 0)
            inputs.emplace(resolvedPath(job.scene), fmt::format("the scene of line {}", job.line));
    std::map<std::string, int> writers;  // resolved output path -> the line writing it
    auto claim = [&](const std::string& path, int line, const std::string& what) -> Status {
        if (path.empty()) return okStatus();
        const std::string resolved = resolvedPath(path);
        auto input = inputs.find(resolved);
        if (input != inputs.end())
            return makeError(ExitCode::Usage, "{}:{}: {}{} would overwrite {}", manifest.path, line,
                             quotedInput(path), what, input->second);
        auto [it, fresh] = writers.emplace(resolved, line);
        if (!fresh)
            return makeError(ExitCode::Usage, "{}:{}: {}{} is also written by line {}", manifest.path, line,
                             quotedInput(path), what, it->second);
        return okStatus();
    };
    // A frame's files: its outputs, then the sidecar that vouches for them.
    auto claimFrame = [&](const BatchFrame& f, int line) -> Status {
        for (const std::string* p : {&f.png, &f.aov, &f.stats}) SR_TRY(claim(*p, line, ""));
        return claim(sidecarPath(f.png), line, " (the sidecar of " + quotedInput(f.png) + ")");
    };
    for (const ManifestJob& job : manifest.jobs) {
        const std::string where = fmt::format("{}:{}", manifest.path, job.line);
        const std::string key = fmt::format(
            "{}\n{}\n{}", job.scene, primitiveModeName(job.options.primitiveMode), job.options.wireframe);
        if (!job.frames) {
            if (!job.orbit.empty())
                return makeError(ExitCode::Usage, "{}: 'orbit' needs 'frames' (a turntable)", where);
            BatchFrame f{&job, 0, 0.0f, job.output, job.aov, job.stats, job.canonical, key};
            SR_TRY(claimFrame(f, job.line));
            frames.push_back(std::move(f));
            continue;
        }
        if (job.orbit.empty()) return makeError(ExitCode::Usage, "{}: 'frames' needs 'orbit' AZ0:AZ1", where);
        auto range = parseAzimuthRange(job.orbit);
        if (!range) return makeError(ExitCode::Usage, "{}: {}", where, range.error().message);
        auto spec = parseCameraSpec(job.options.camera);
        if (spec->kind == CameraSpec::Kind::Gltf)
            return makeError(ExitCode::Usage,
                             "{}: a turntable orbits the scene: 'camera' must be auto or orbit:...", where);
        // The patterns are the paths as written (a % in the manifest's folder is no conversion), joined to
        // the manifest's folder once expanded.
        std::optional<FramePattern> png, aov, stats;
        auto pattern = [&](const char* option, const std::string& path,
                           std::optional<FramePattern>& out) -> Status {
            if (path.empty()) return okStatus();
            auto p = parseFramePattern(option, path);
            if (!p) return makeError(ExitCode::Usage, "{}: {}", where, p.error().message);
            out = *p;
            return okStatus();
        };
        SR_TRY(pattern("output", job.outputPattern, png));
        SR_TRY(pattern("aov", job.aovPattern, aov));
        SR_TRY(pattern("stats", job.statsPattern, stats));
        for (uint32_t k = 0; k < job.frames; ++k) {
            BatchFrame f;
            f.job = &job;
            f.frame = k;
            f.azimuthDeg = turntableAzimuth(*range, k, job.frames);
            f.png = joinPath(manifest.baseDir, framePath(*png, k));
            f.aov = aov ? joinPath(manifest.baseDir, framePath(*aov, k)) : "";
            f.stats = stats ? joinPath(manifest.baseDir, framePath(*stats, k)) : "";
            f.settings = job.canonical;
            f.settings["frame"] = k;
            f.sceneKey = key;
            SR_TRY(claimFrame(f, job.line));
            frames.push_back(std::move(f));
        }
    }
    return frames;
}

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Host memory a worker's colour images are written into by the render itself (RenderRequest::targets):
// page-locked on a CUDA device, so the copy runs at the bus's speed, and reused, so no frame pays for a
// fresh 8 MB allocation. A frame's buffer comes back when its files are written.
class ColorPool {
public:
    Result<raster::Memory> take(raster::Device& device, size_t bytes)
    {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            for (size_t i = 0; i < free_.size(); ++i)
                if (free_[i].size() == bytes) {
                    raster::Memory memory = std::move(free_[i]);
                    free_.erase(free_.begin() + std::ptrdiff_t(i));
                    return memory;
                }
        }
        auto memory = raster::Memory::allocate(device, bytes);
        if (!memory) return raster::fromPublic(memory.error());
        return std::move(*memory);
    }
    void give(raster::Memory memory)
    {
        std::lock_guard<std::mutex> lock(mutex_);
        free_.push_back(std::move(memory));
    }

private:
    std::mutex mutex_;
    std::vector<raster::Memory> free_;
};

// A rendered frame on its way to the I/O threads: its colour in a pool's buffer, the rest in the Frame.
struct Finished {
    size_t frame = 0;  // index into the expanded frames
    raster::Frame image;
    sr::AovImage surface;  // the frame's surface AOVs as planes, for its EXR
    std::optional<raster::Memory> color;
    std::shared_ptr<ColorPool> pool;
    double gpuMs = 0.0, renderMs = 0.0;
};

// Per-frame times, ms.
struct FrameTimes {
    double gpu = 0, render = 0, encode = 0, aux = 0, write = 0;
};

struct Failure {
    size_t frame;
    std::string error;
};

// Finished frames between the workers and the I/O threads: push blocks while `capacity` frames wait
// (so a fast GPU cannot fill the memory with frames the disk has not taken), pop blocks while none
// does, until close().
class FrameQueue {
public:
    explicit FrameQueue(size_t capacity) : capacity_(capacity) {}

    // Returns the ms spent waiting for room.
    double push(Finished&& item)
    {
        const auto start = Clock::now();
        std::unique_lock<std::mutex> lock(mutex_);
        notFull_.wait(lock, [&] { return items_.size() < capacity_; });
        const double waited = msSince(start);
        items_.push_back(std::move(item));
        notEmpty_.notify_one();
        return waited;
    }
    bool pop(Finished& item)
    {
        std::unique_lock<std::mutex> lock(mutex_);
        notEmpty_.wait(lock, [&] { return !items_.empty() || closed_; });
        if (items_.empty()) return false;
        item = std::move(items_.front());
        items_.pop_front();
        notFull_.notify_one();
        return true;
    }
    void close()
    {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
        notEmpty_.notify_all();
    }

private:
    size_t capacity_;
    std::mutex mutex_;
    std::condition_variable notFull_, notEmpty_;
    std::deque<Finished> items_;
    bool closed_ = false;
};

// A scene loaded on a thread of its own, as raster::Scene::load reads it (its warnings printed).
struct LoadedScene {
    Result<std::shared_ptr<const raster::Scene>> scene = makeError(ExitCode::Usage, "not loaded");
    double ms = 0.0;
};

LoadedScene loadFrameScene(const ManifestJob& job)
{
    const auto start = Clock::now();
    LoadedScene loaded;
    auto scene = raster::Scene::load(job.scene);
    if (scene) {
        for (const std::string& warning : scene->warnings()) warnLine(warning);
        loaded.scene =
            std::shared_ptr<const raster::Scene>(std::make_shared<raster::Scene>(std::move(*scene)));
    } else {
        loaded.scene = raster::fromPublic(scene.error());
    }
    loaded.ms = msSince(start);
    return loaded;
}

// The scenes of the pending frames, each loaded once (whichever worker asks first, or ahead of time
// while the previous scene renders) and dropped when no frame left to hand out needs it; a worker holds
// its current scene itself.
class SceneCache {
public:
    SceneCache(const std::vector<BatchFrame>& frames, const std::vector<size_t>& pending)
        : frames_(frames), pending_(pending)
    {
        for (size_t i = 0; i < pending.size(); ++i) last_[frames[pending[i]].sceneKey] = i;
    }

    // The scene of pending frame `i` (waiting for its load), with the next scene's load started.
    LoadedScene get(size_t i)
    {
        std::shared_future<LoadedScene> scene = request(i);
        const std::string& key = frames_[pending_[i]].sceneKey;
        for (size_t j = i + 1; j < pending_.size(); ++j)
            if (frames_[pending_[j]].sceneKey != key) {
                request(j);
                break;
            }
        LoadedScene loaded = scene.get();
        std::lock_guard<std::mutex> lock(mutex_);
        if (counted_.insert(key).second) {
            ++loads_;
            loadMs_ += loaded.ms;
        }
        // Frames up to i are handed out: a scene none of the later ones uses is needed only by the
        // workers that hold it already.
        for (auto it = entries_.begin(); it != entries_.end();)
            it = last_[it->first] < i ? entries_.erase(it) : std::next(it);
        return loaded;
    }

    size_t loads() const { return loads_; }
    double loadMs() const { return loadMs_; }

private:
    std::shared_future<LoadedScene> request(size_t i)
    {
        const BatchFrame& f = frames_[pending_[i]];
        std::lock_guard<std::mutex> lock(mutex_);
        auto it = entries_.find(f.sceneKey);
        if (it != entries_.end()) return it->second;
        const ManifestJob* job = f.job;
        auto future = std::async(std::launch::async, [job] { return loadFrameScene(*job); }).share();
        entries_.emplace(f.sceneKey, future);
        return future;
    }

    const std::vector<BatchFrame>& frames_;
    const std::vector<size_t>& pending_;
    std::unordered_map<std::string, size_t> last_;  // scene key -> last pending index drawing it
    std::mutex mutex_;
    std::map<std::string, std::shared_future<LoadedScene>> entries_;
    std::set<std::string> counted_;
    size_t loads_ = 0;
    double loadMs_ = 0.0;
};

// The backend and the device indices the workers open, from the devices the library offers
// (raster::devices): the backend's first device without --devices; with it, auto becomes whichever
// backend has the first listed device (so that the workers never mix backends), and `all` is every
// device that is not a CPU implementation (lavapipe), or device 0 when there is no other.
Result<std::vector<int>> resolveDevices(raster::Backend& kind, const std::string& text)
{
    if (text.empty()) return std::vector<int>{-1};
    auto list = parseDeviceList(text);
    if (!list) return list.error();
    const std::vector<raster::DeviceInfo> offered = raster::devices();
    if (kind == raster::Backend::Auto) {
        const int first = list->all ? 0 : list->indices.front();
        const bool cuda = std::any_of(offered.begin(), offered.end(), [&](const raster::DeviceInfo& d) {
            return d.backend == raster::Backend::Cuda && d.index == first;
        });
        kind = cuda ? raster::Backend::Cuda : raster::Backend::Vulkan;
    }
    if (!list->all) return list->indices;
    std::vector<int> devices;
    for (const raster::DeviceInfo& d : offered)
        if (d.backend == kind && !d.cpu) devices.push_back(d.index);
    if (devices.empty()) {
        // No GPU of the backend: its first device (lavapipe), or the reason it has none.
        auto first = raster::Device::open(kind, 0);
        if (!first) return raster::fromPublic(first.error());
        devices.push_back(0);
    }
    return devices;
}

nlohmann::json spread(std::vector<double> values)
{
    if (values.empty()) return nullptr;
    double sum = 0.0;
    for (double v : values) sum += v;
    const double max = *std::max_element(values.begin(), values.end());
    return {{"mean", sum / double(values.size())}, {"median", median(std::move(values))}, {"max", max}};
}

double mean(const std::vector<double>& values)
{
    double sum = 0.0;
    for (double v : values) sum += v;
    return values.empty() ? 0.0 : sum / double(values.size());
}

struct WorkerReport {
    int index = -1;
    raster::DeviceInfo device;
    size_t frames = 0;
    double gpuMs = 0.0, renderMs = 0.0, waitMs = 0.0;
};

// The state the workers and the I/O threads share.
class BatchRun {
public:
    BatchRun(const BatchOptions& options, const std::vector<BatchFrame>& frames, std::vector<size_t> pending,
             size_t ioThreads, size_t queueFrames)
        : options_(options),
          frames_(frames),
          pending_(std::move(pending)),
          ioThreads_(ioThreads),
          queue_(queueFrames),
          scenes_(frames_, pending_),
          progress_(!options.quiet && isatty(STDERR_FILENO))
    {
    }

    // Renders every pending frame on `devices` of `kind`; an error only when a device cannot be opened.
    Status run(raster::Backend kind, const std::vector<int>& devices)
    {
        reports_.resize(devices.size());
        std::vector<std::promise<Status>> opened(devices.size());
        std::promise<bool> go;
        std::shared_future<bool> start = go.get_future().share();
        std::vector<std::thread> workers;
        for (size_t w = 0; w < devices.size(); ++w)
            workers.emplace_back([&, w] { work(kind, devices[w], reports_[w], opened[w], start); });
        // Every device opens before anything renders, so that a bad index is a usage error, not a batch
        // of failed jobs.
        std::optional<Error> failure;
        for (auto& o : opened) {
            Status status = o.get_future().get();
            if (!status && !failure) failure = status.error();
        }
        start_ = Clock::now();
        go.set_value(!failure);
        std::vector<std::thread> writers;
        if (!failure)
            for (size_t t = 0; t < ioThreads_; ++t) writers.emplace_back([&] { write(); });
        for (auto& t : workers) t.join();
        queue_.close();
        for (auto& t : writers) t.join();
        wallS_ = std::chrono::duration<double>(Clock::now() - start_).count();
        if (progress_) fmt::print(stderr, "\n");
        if (failure) return *failure;
        return okStatus();
    }

    nlohmann::json summary() const
    {
        std::vector<double> gpu, render, encode, aux, write, io;
        for (const FrameTimes& t : times_) {
            gpu.push_back(t.gpu);
            render.push_back(t.render);
            encode.push_back(t.encode);
            aux.push_back(t.aux);
            write.push_back(t.write);
            io.push_back(t.encode + t.aux + t.write);
        }
        nlohmann::json devices = nlohmann::json::array();
        for (const WorkerReport& r : reports_)
            devices.push_back({{"index", r.index},
                               {"backend", raster::backendName(r.device.backend)},
                               {"name", r.device.name},
                               {"frames", r.frames},
                               {"gpu_ms", r.gpuMs},
                               {"render_ms", r.renderMs},
                               {"queue_wait_ms", r.waitMs}});
        nlohmann::json failed = nlohmann::json::array();
        for (const Failure& f : failures_) {
            const BatchFrame& frame = frames_[f.frame];
            // Bounded as messages quote input: no real path is longer than PATH_MAX (4096 bytes).
            nlohmann::json entry{{"line", frame.job->line},
                                 {"id", clippedText(frame.job->id, 4096)},
                                 {"output", clippedText(frame.png, 4096)},
                                 {"error", f.error}};
            if (frame.job->frames) entry["frame"] = frame.frame;
            failed.push_back(std::move(entry));
        }
        // What each side could sustain alone: the workers rendering back to back, the I/O threads writing
        // back to back. The smaller one is the batch's limit.
        const double renderFps = render.empty() ? 0.0 : 1000.0 * double(reports_.size()) / mean(render);
        const double ioFps = io.empty() ? 0.0 : 1000.0 * double(ioThreads_) / mean(io);
        return {{"rendered", times_.size()},
                {"failed", failures_.size()},
                {"wall_s", wallS_},
                {"fps", wallS_ > 0.0 ? double(times_.size()) / wallS_ : 0.0},
                {"devices", devices},
                {"io_threads", ioThreads_},
                {"per_frame_ms",
                 {{"gpu", spread(gpu)},
                  {"render", spread(render)},
                  {"encode", spread(encode)},
                  {"aux", spread(aux)},
                  {"write", spread(write)}}},
                {"scene_loads", {{"count", scenes_.loads()}, {"total_ms", scenes_.loadMs()}}},
                {"limit",
                 {{"render_fps", renderFps},
                  {"io_fps", ioFps},
                  {"bound", times_.empty()       ? "none"
                            : renderFps <= ioFps ? "render"
                                                 : "io"}}},
                {"failures", failed}};
    }

    bool anyFailed() const { return !failures_.empty(); }

private:
    void fail(size_t frame, const std::string& error)
    {
        std::lock_guard<std::mutex> lock(mutex_);
        failures_.push_back({frame, error});
        const BatchFrame& f = frames_[frame];
        if (progress_) fmt::print(stderr, "\n");
        fmt::print(stderr, "raster: job failed: {}:{}{}: {}\n", options_.manifest, f.job->line,
                   f.job->frames ? fmt::format(" frame {}", f.frame) : "", error);
        showProgress(true);
    }

    // A worker: opens its device, then takes the next pending frame until none is left.
    void work(raster::Backend kind, int index, WorkerReport& report, std::promise<Status>& opened,
              std::shared_future<bool> start)
    {
        // The workers' devices are released one at a time (taken when this worker's frames are done,
        // released after its device): two Vulkan devices torn down at once on two threads left a batch
        // of two H200s hanging after its last frame, in the driver, in about one run of three.
        std::unique_lock<std::mutex> teardown(teardownMutex_, std::defer_lock);
        // Opened on this thread: a CUDA device is current per thread.
        auto device = raster::Device::open(kind, index);
        report.index = index < 0 ? 0 : index;
        if (device) report.device = device->info();
        opened.set_value(device ? okStatus() : Status(raster::fromPublic(device.error())));
        if (!device || !start.get()) return;
        std::string sceneKey;
        std::shared_ptr<const raster::Scene> scene;
        std::optional<raster::Session> session;
        auto pool = std::make_shared<ColorPool>();
        std::string sceneError;
        for (;;) {
            const size_t i = next_.fetch_add(1);
            if (i >= pending_.size()) break;
            const size_t frameIndex = pending_[i];
            const BatchFrame& f = frames_[frameIndex];
            if (f.sceneKey != sceneKey) {
                // The previous scene's session goes first: it uses the device's buffers.
                session.reset();
                scene.reset();
                sceneKey = f.sceneKey;
                LoadedScene loaded = scenes_.get(i);
                if (loaded.scene) {
                    scene = *loaded.scene;
                    auto created = raster::Session::create(*device, *scene);
                    if (created)
                        session.emplace(std::move(*created));
                    else
                        sceneError = created.error().message;
                } else {
                    sceneError = loaded.scene.error().message;
                }
            }
            if (!session) {
                fail(frameIndex, sceneError);
                continue;
            }
            const ManifestJob& job = *f.job;
            // warmup and repeat as the job says (`raster batch` defaults warmup to 0: a warm-up run would
            // change nothing in the images). The ids and depth (stage aovs) and the surface channels only
            // for a job with an EXR.
            raster::RenderRequest request;
            request.surfaceAovs = !f.aov.empty();
            request.outputs = f.aov.empty() ? raster::OutputColor : raster::OutputImages;
            request.stats = !f.stats.empty();
            const auto renderStart = Clock::now();
            auto color =
                pool->take(*device, size_t(job.options.settings.width) * job.options.settings.height * 4);
            if (!color) {
                fail(frameIndex, color.error().message);
                continue;
            }
            request.targets.color = color->data();
            auto camera = frameCamera(f, *scene);
            if (!camera) {
                fail(frameIndex, camera.error().message);
                continue;
            }
            // The surface AOVs as the EXR's planes (the frame's interleaved arrays are for API callers).
            Finished finished;
            raster::Internal::RenderControl control;
            control.aovPlanes = &finished.surface;
            auto frame = raster::Internal::render(
                *session, *camera, raster::Internal::makeSettings(job.options), request, control);
            if (!frame) {
                fail(frameIndex, frame.error().message);
                continue;
            }
            warnOnce(f, frame->warnings);
            finished.frame = frameIndex;
            finished.renderMs = msSince(renderStart);
            finished.gpuMs = frame->gpuMs;
            finished.image = std::move(*frame);
            finished.color = std::move(*color);
            finished.pool = pool;
            report.frames++;
            report.gpuMs += finished.gpuMs;
            report.renderMs += finished.renderMs;
            report.waitMs += queue_.push(std::move(finished));
        }
        teardown.lock();
    }

    // One warning line per job (the first of its frames to meet it), above the progress line.
    void warnOnce(const BatchFrame& f, const std::vector<std::string>& warnings)
    {
        if (warnings.empty()) return;
        std::lock_guard<std::mutex> lock(mutex_);
        if (!warnedJobs_.insert(f.job).second) return;
        if (progress_) fmt::print(stderr, "\n");
        for (const std::string& w : warnings)
            fmt::print(stderr, "warning: {}:{}: {}\n", options_.manifest, f.job->line, w);
    }

    // Frame k of a turntable is `raster render --camera orbit:AZk,...` (the turntable's camera model);
    // any other job draws with its settings' camera.
    static Result<raster::Camera> frameCamera(const BatchFrame& f, const raster::Scene& scene)
    {
        if (!f.job->frames) return raster::Camera::fromSpec("auto");
        auto orbit = turntableOrbit(scene, f.job->options);
        if (!orbit) return orbit.error();
        OrbitPose pose = orbit->pose();
        pose.azimuthDeg = f.azimuthDeg;
        return raster::Camera::fromSpec(orbitSpecString(pose));
    }

    // An I/O thread: encodes and writes finished frames until the queue closes.
    void write()
    {
        Finished item;
        while (queue_.pop(item)) {
            FrameTimes times;
            times.gpu = item.gpuMs;
            times.render = item.renderMs;
            Status status = commit(item, times);
            const size_t frame = item.frame;
            // The frame's images are freed before waiting for the next one.
            item = Finished{};
            if (!status) {
                fail(frame, status.error().message);
                continue;
            }
            std::lock_guard<std::mutex> lock(mutex_);
            times_.push_back(times);
            showProgress(false);
        }
    }

    // The frame's files and then its sidecar under temporary names, all renamed into place together
    // (FileGroup): a job with a sidecar that matches has all its files whole, and a job that fails
    // leaves none of them.
    Status commit(Finished& item, FrameTimes& times)
    {
        const BatchFrame& f = frames_[item.frame];
        const std::string sidecar = sidecarPath(f.png);
        // An old sidecar must not vouch for files this run is replacing (anything else at its path, such
        // as a folder, stays, and the commit reports it).
        if (checkOutputTarget(sidecar)) std::remove(sidecar.c_str());
        for (const std::string* path : {&f.png, &f.aov, &f.stats})
            if (!path->empty()) SR_TRY(createParentFolder(*path));
        FileGroup files;
        OutputTimes spent;
        if (item.color) {
            // The colour the render wrote into the pool's buffer: into the frame, and the buffer back.
            const auto* bytes = static_cast<const uint8_t*>(item.color->data());
            item.image.color.assign(bytes, bytes + item.color->size());
            item.pool->give(std::move(*item.color));
            item.color.reset();
        }
        SR_TRY(stageFrame(files, item.image, OutputPaths{f.png, f.aov, f.stats}, f.job->encoding, &spent,
                          &item.surface));
        times.encode = spent.encode;
        times.aux = spent.aux;
        auto start = Clock::now();
        const std::string text = sidecarJson(f.settings, f.job->scene).dump(2) + "\n";
        SR_TRY(files.stage(sidecar, text.data(), text.size()));
        if (options_.ioDelayMs) std::this_thread::sleep_for(std::chrono::milliseconds(options_.ioDelayMs));
        SR_TRY(files.commit());
        times.write = spent.write + msSince(start) - options_.ioDelayMs;
        return okStatus();
    }

    // The progress line (a terminal only), at most 10 times a second unless `force`. Call with mutex_.
    void showProgress(bool force)
    {
        if (!progress_) return;
        const auto now = Clock::now();
        if (!force && now - lastProgress_ < std::chrono::milliseconds(100) &&
            times_.size() + failures_.size() < pending_.size())
            return;
        lastProgress_ = now;
        const size_t done = times_.size() + failures_.size();
        const double s = std::chrono::duration<double>(now - start_).count();
        const double fps = s > 0.0 ? double(times_.size()) / s : 0.0;
        const std::string eta =
            fps > 0.0 ? fmt::format("{:.0f} s", double(pending_.size() - done) / fps) : std::string("?");
        fmt::print(stderr, "\rbatch: {}/{} frames, {:.1f} fps, ETA {}{}   ", done, pending_.size(), fps, eta,
                   failures_.empty() ? "" : fmt::format(", {} failed", failures_.size()));
        std::fflush(stderr);
    }

    const BatchOptions& options_;
    const std::vector<BatchFrame>& frames_;
    const std::vector<size_t> pending_;
    const size_t ioThreads_;
    FrameQueue queue_;
    SceneCache scenes_;
    const bool progress_;
    std::atomic<size_t> next_{0};
    std::vector<WorkerReport> reports_;
    std::mutex mutex_;          // times_, failures_, warnedJobs_, the progress line
    std::mutex teardownMutex_;  // one worker's device released at a time
    std::set<const ManifestJob*> warnedJobs_;
    std::vector<FrameTimes> times_;
    std::vector<Failure> failures_;
    Clock::time_point start_ = Clock::now(), lastProgress_;
    double wallS_ = 0.0;
};

}  // namespace

Result<bool> runBatch(const BatchOptions& options)
{
    // Everything that can be wrong with the request is reported before any device opens.
    auto shard = chooseShard(options.shard, slurmEnvironment());
    if (!shard) return shard.error();
    auto manifest = loadManifest(options.manifest, options.defaults);
    if (!manifest) return manifest.error();
    auto frames = expandJobs(*manifest);
    if (!frames) return frames.error();
    auto parsed = raster::parseBackend(options.backend);
    if (!parsed) return raster::fromPublic(parsed.error());
    raster::Backend kind = *parsed;
    if (!options.devices.empty()) {
        auto list = parseDeviceList(options.devices);
        if (!list) return list.error();
    }

    std::vector<size_t> mine;
    std::vector<std::string> finals;
    for (size_t i = 0; i < frames->size(); ++i)
        if (inShard(*shard, i)) {
            mine.push_back(i);
            for (const std::string* p : {&(*frames)[i].png, &(*frames)[i].aov, &(*frames)[i].stats})
                if (!p->empty()) finals.push_back(*p);
            finals.push_back(sidecarPath((*frames)[i].png));
        }
    const size_t leftovers = removeTemporaries(finals);
    std::vector<size_t> pending;
    size_t skipped = 0;
    for (size_t i : mine) {
        const BatchFrame& f = (*frames)[i];
        std::vector<std::string> outputs;
        for (const std::string* p : {&f.png, &f.aov, &f.stats})
            if (!p->empty()) outputs.push_back(*p);
        if (!options.force && jobComplete(sidecarPath(f.png), sidecarJson(f.settings, f.job->scene), outputs))
            ++skipped;
        else
            pending.push_back(i);
    }
    // The frames of one scene one after another (in manifest order within it), so that each worker
    // loads a scene once and keeps its session; the scenes in the order they first appear.
    std::map<std::string, size_t> firstSeen;
    for (size_t i : pending) firstSeen.emplace((*frames)[i].sceneKey, firstSeen.size());
    std::stable_sort(pending.begin(), pending.end(), [&](size_t a, size_t b) {
        return firstSeen[(*frames)[a].sceneKey] < firstSeen[(*frames)[b].sceneKey];
    });

    nlohmann::json summary{
        {"manifest", options.manifest},
        {"shard", {{"index", shard->index}, {"count", shard->count}, {"source", shard->source}}},
        {"jobs",
         {{"manifest", frames->size()},
          {"shard", mine.size()},
          {"skipped", skipped},
          {"pending", pending.size()}}},
        {"removed_temporaries", leftovers}};
    bool ok = true;
    if (!pending.empty()) {
        // A resumed shard with nothing left to do needs no device at all.
        auto devices = resolveDevices(kind, options.devices);
        if (!devices) return devices.error();
        // Encoding is the I/O threads' work and scales with them (each frame on one core), so every core
        // a device's worker leaves idle gets one; on a many-core node a cap would leave them unused.
        const size_t cores = std::max(1u, std::thread::hardware_concurrency());
        const size_t ioThreads =
            options.ioThreads ? options.ioThreads : (cores > devices->size() ? cores - devices->size() : 1);
        const size_t queueFrames = options.queueFrames ? options.queueFrames : 2 * ioThreads;
        BatchRun run(options, *frames, pending, ioThreads, queueFrames);
        SR_TRY(run.run(kind, *devices));
        summary.update(run.summary());
        ok = !run.anyFailed();
    } else {
        summary.update({{"rendered", 0},
                        {"failed", 0},
                        {"wall_s", 0.0},
                        {"fps", 0.0},
                        {"failures", nlohmann::json::array()}});
    }
    if (!options.summaryPath.empty()) {
        SR_TRY(createParentFolder(options.summaryPath));
        const std::string text = summary.dump(2) + "\n";
        SR_TRY(writeFileAtomically(options.summaryPath, text.data(), text.size()));
    }
    if (!options.quiet) fmt::print("{}\n", summary.dump(2));
    return ok;
}

}  // namespace sr
