#include "msim/scene/interrupt.hpp"

#include <atomic>
#include <csignal>

namespace msim::scene {

namespace {
std::atomic<bool> gInterrupted{false};
// First signal: ask the loop to stop after the frame in progress. A second one gets the default
// action (terminate); frames are written atomically, so even that leaves no half-written frame.
extern "C" void onSignal(int signal) {
  gInterrupted.store(true);
  std::signal(signal, SIG_DFL);
}
}  // namespace

void installInterruptHandler() {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  // Under mpirun, Ctrl-C ends the whole job at once; mpirun forwards SIGUSR1 to every process, so
  // it is the way to stop a split run after its frame (kill -USR1 on mpirun's process).
  std::signal(SIGUSR1, onSignal);
}

bool interruptRequested() { return gInterrupted.load(); }
void requestInterrupt() { gInterrupted.store(true); }

}  // namespace msim::scene
