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
}

bool interruptRequested() { return gInterrupted.load(); }
void requestInterrupt() { gInterrupted.store(true); }

}  // namespace msim::scene
