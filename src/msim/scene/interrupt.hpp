#pragma once
// Ctrl-C (SIGINT), SIGTERM and SIGUSR1 (which mpirun forwards to its processes) ask the run to
// stop: the time loop finishes the frame file it is writing, records the run as interrupted and
// exits; nothing half-written is left behind.
// A second signal terminates at once (still no half-written frame: files are renamed into place).
namespace msim::scene {

void installInterruptHandler();
bool interruptRequested();
void requestInterrupt();  // what the handler does; tests call it directly

}  // namespace msim::scene
