#pragma once
// SIGINT, SIGTERM and SIGHUP ask `chimera run` to stop cleanly: the handler only sets a flag that
// the main loop polls, because nothing else is safe inside a signal handler.

namespace chimera::cli {

/// Installs the handlers (without SA_RESTART, so a blocking poll() returns early), and ignores
/// SIGPIPE. Signals within a second of the first are the same request; one after that ends the
/// process the default way, for a stuck stop, after removing the names of the shared memory
/// this process owns.
void install_stop_handlers();
/// Whether SIGINT, SIGTERM or SIGHUP has arrived, or request_stop() was called.
bool stop_requested();
/// Asks for the same clean stop as a signal (the network API's `quit`); a signal within a
/// second after it is the same request. Any thread.
void request_stop();

}  // namespace chimera::cli
