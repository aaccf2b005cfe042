#pragma once
// Cooperative cancellation: SIGINT/SIGTERM set a flag that long loops poll with
// ThrowIfCancelled(), so staging folders and temporary files are cleaned up by
// ordinary destructors instead of being left half-written.

namespace irbench {

// Installs handlers for SIGINT and SIGTERM.
void InstallCancelHandlers();
bool CancelRequested();
// Throws Cancelled if a signal arrived.
void ThrowIfCancelled();
// For tests.
void RequestCancel();
void ResetCancel();

}  // namespace irbench
