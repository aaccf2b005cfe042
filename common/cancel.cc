#include "common/cancel.h"

#include <atomic>
#include <csignal>

#include "common/error.h"

namespace irbench {
namespace {

volatile std::sig_atomic_t g_cancel = 0;

// Loops poll the flag at least once per camera render (tens of milliseconds),
// so a single signal ends a run promptly and cleanly; further signals change
// nothing, so an impatient second Ctrl-C cannot leave a staging folder behind.
void OnSignal(int) { g_cancel = 1; }

}  // namespace

void InstallCancelHandlers() {
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool CancelRequested() { return g_cancel != 0; }

void ThrowIfCancelled() {
  if (g_cancel != 0) throw Cancelled();
}

void RequestCancel() { g_cancel = 1; }
void ResetCancel() { g_cancel = 0; }

}  // namespace irbench
