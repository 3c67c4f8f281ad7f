// The progress, Ctrl-C and run limits of a long call from Python (weft_python.h).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>

#include "weft/core/error.h"
#include "weft_python.h"

namespace weft::python {

namespace {
using Clock = std::chrono::steady_clock;
constexpr double kPrintEverySeconds = 2.0;

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// A line on Python's sys.stderr (a notebook shows it, unlike the C stderr). Takes the GIL.
void print_stderr(const std::string& text) {
  py::gil_scoped_acquire gil;
  py::module_::import("sys").attr("stderr").attr("write")(text);
}
}  // namespace

struct CallProgress::State {
  bool print = false;
  std::thread::id caller = std::this_thread::get_id();
  std::mutex mutex;  // the fields below
  bool interrupted = false;
  std::string stage;
  bool stage_end_printed = false;
  Clock::time_point stage_start = Clock::now(), last_print;
};

CallProgress::CallProgress(bool print) : state_(std::make_shared<State>()) {
  state_->print = print;
}

bool CallProgress::interrupted() const {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->interrupted;
}

void CallProgress::note(const std::string& line) const {
  if (state_->print) print_stderr(line);
}

void CallProgress::raise_if_interrupted() const {
  if (!interrupted()) return;
  PyErr_SetNone(PyExc_KeyboardInterrupt);
  throw py::error_already_set();
}

ProgressCallback CallProgress::callback() {
  std::shared_ptr<State> s = state_;
  return [s](const ProgressUpdate& u) {
    // Ctrl-C: Python's handler runs only on the main thread, so only the caller's thread asks.
    if (std::this_thread::get_id() == s->caller) {
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {
        PyErr_Clear();
        const std::lock_guard<std::mutex> lock(s->mutex);
        s->interrupted = true;
      }
    }
    std::string line;
    {
      const std::lock_guard<std::mutex> lock(s->mutex);
      if (s->interrupted) return false;
      if (!s->print) return true;
      const Clock::time_point now = Clock::now();
      if (u.stage != s->stage) {
        s->stage = std::string(u.stage);
        s->stage_start = now;
        s->last_print = {};
        s->stage_end_printed = false;
      }
      const bool end = u.total > 0 && u.done >= u.total;
      if (end ? s->stage_end_printed : seconds_between(s->last_print, now) < kPrintEverySeconds)
        return true;
      s->stage_end_printed = end;
      s->last_print = now;
      line = format_progress_line(u, seconds_between(s->stage_start, now)) + "\n";
    }
    print_stderr(line);
    return true;
  };
}

RunLimits call_limits(bool yes_long) {
  RunLimits l;
  l.yes_long = yes_long;
  l.announce = [](const std::string& line) { std::fprintf(stderr, "weft: %s\n", line.c_str()); };
  return l;
}

}  // namespace weft::python
