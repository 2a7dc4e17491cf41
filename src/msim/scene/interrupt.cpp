#include "msim/scene/interrupt.hpp"

#include <atomic>
#include <csignal>

namespace msim::scene {

namespace {
std::atomic<bool> gInterrupted{false};
extern "C" void onSignal(int) { gInterrupted.store(true); }
}  // namespace

void installInterruptHandler() {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
}

bool interruptRequested() { return gInterrupted.load(); }
void requestInterrupt() { gInterrupted.store(true); }

}  // namespace msim::scene
