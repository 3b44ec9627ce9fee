// Progress of a long solve, for the person waiting at the terminal: a line when a stage starts
// (what it is and how big), and a rate-limited heartbeat from inner loops (the QP's iterations and
// projected gradient every few seconds). The solver only calls it; the CLI decides where the lines
// go (stdout, or nowhere with --quiet). A default-constructed Progress is silent.
#pragma once

#include <chrono>
#include <functional>
#include <string>

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
    if (!heartbeat_ || (started_ && ++calls_ % kClockEvery != 0)) return;
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
