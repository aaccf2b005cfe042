#include "common/cancel.h"

#include <unistd.h>

#include <atomic>
#include <csignal>

#include "common/error.h"

namespace irbench {
namespace {

volatile std::sig_atomic_t g_cancel = 0;

void OnSignal(int signal) {
  if (g_cancel != 0) _exit(128 + signal);  // a second Ctrl-C: give up at once
  g_cancel = 1;
}

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
