// Progress of a long solve, for the person waiting at the terminal: a line when a stage starts
// (what it is and how big), and a rate-limited heartbeat from inner loops (the QP's iterations and
// projected gradient every few seconds) — or, around a long call that has no loop of ours to beat in
// (the mesher, a sparse factorization), a Watch: a line from a thread of its own every kWatchPeriod
// seconds saying what still runs and for how long. The solver only calls it; the CLI decides where
// the lines go (stdout, or nowhere with --quiet). A default-constructed Progress is silent.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace contact3d {

class Progress {
 public:
  using Sink = std::function<void(const std::string& line)>;

  Progress() = default;
  // `stages` gets the stage lines; `heartbeat` (may be empty) at most one line per `period_s`.
  Progress(Sink stages, Sink heartbeat, double period_s)
      : stages_(std::move(stages)), heartbeat_(std::move(heartbeat)), period_(period_s) {}

  void stage(const std::string& line) const {
    if (stages_) stages_(line);
  }
  // Call as often as wanted from a loop (the clock is read every kClockEvery calls, so an inner
  // loop pays a counter increment); `make_line()` runs only when a heartbeat line is due.
  template <class MakeLine>
  void beat(MakeLine make_line) {
    if (started_ && ++calls_ % kClockEvery != 0) return;
    beat_each_call(make_line);
  }
  // The same from a loop whose every pass costs far more than reading the clock (a Newton step, a CG
  // iteration whose product goes through the factor of K): the clock is read on every call. Once every
  // 32 Newton steps left a helper's matrix-free solve silent for up to 261 s.
  template <class MakeLine>
  void beat_each_call(MakeLine make_line) {
    if (!heartbeat_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!started_) {
      started_ = true;
      last_ = start_ = now;
      return;
    }
    if (std::chrono::duration<double>(now - last_).count() < period_) return;
    last_ = now;
    heartbeat_(make_line());
  }
  // While it lives, a line "  <what>: still running, N s" every kWatchPeriod seconds (on the heartbeat's
  // sink; none where the Progress is silent). The thread that made it is inside the long call and
  // prints nothing meanwhile.
  class Watch {
   public:
    static constexpr double kWatchPeriod = 30;
    Watch(const Progress& progress, std::string what, double period_s = kWatchPeriod) {
      if (!progress.heartbeat_) return;
      thread_ = std::thread([this, sink = progress.heartbeat_, what = std::move(what), period_s] {
        const auto start = std::chrono::steady_clock::now();
        std::unique_lock<std::mutex> lock(mutex_);
        for (int k = 1; !cv_.wait_for(
                 lock, std::chrono::duration<double>(period_s * k) - (std::chrono::steady_clock::now() - start),
                 [this] { return done_; });
             ++k)
          sink("  " + what + ": still running, " + seconds_text(period_s * k) + " s");
      });
    }
    ~Watch() {
      if (!thread_.joinable()) return;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        done_ = true;
      }
      cv_.notify_one();
      thread_.join();
    }
    Watch(const Watch&) = delete;
    Watch& operator=(const Watch&) = delete;

   private:
    static std::string seconds_text(double s) {
      return s >= 1 ? std::to_string(static_cast<long>(s)) : std::to_string(s).substr(0, 4);
    }
    std::mutex mutex_;
    std::condition_variable cv_;
    bool done_ = false;
    std::thread thread_;
  };

  // A new inner solve starts: its first heartbeat comes one period after its first beat().
  void restart() { started_ = false; }
  // Seconds since the inner solve's first beat().
  double elapsed() const {
    return started_ ? std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count() : 0.0;
  }

 private:
  Sink stages_, heartbeat_;
  static constexpr unsigned kClockEvery = 32;
  double period_ = 2.0;
  unsigned calls_ = 0;
  bool started_ = false;
  std::chrono::steady_clock::time_point last_, start_;
};

}  // namespace contact3d
