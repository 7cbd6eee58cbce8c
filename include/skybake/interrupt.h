// skybake/interrupt.h: stopping long work cleanly on SIGINT or SIGTERM.
//
// A program that installs the handlers (the CLI does) gets its long loops
// (bakes, renders, training, imports) stopped at their next progress step
// with skybake::Interrupted, which unwinds like any error: temporary output
// files are removed and no target is written. A second signal ends the
// process at once.
#pragma once

#include "skybake/error.h"

namespace skybake {

// Thrown by check_interrupted() after a SIGINT or SIGTERM.
class Interrupted : public Error {
public:
    explicit Interrupted(int signal);
    int signal() const noexcept { return signal_; }

private:
    int signal_;
};

// Installs handlers for SIGINT and SIGTERM that record the signal.
void install_interrupt_handlers();
// The recorded signal, or 0.
int interrupt_signal();
// Throws Interrupted if a signal was recorded. Cheap: call it in loops.
void check_interrupted();

// For hosts that own the signal handlers (the Python module): records
// `signal` as a handler of theirs received it, so that every loop that calls
// check_interrupted() stops; safe to call from a signal handler (one atomic
// store). clear_interrupt() forgets it, before the host's next long call.
void request_interrupt(int signal) noexcept;
void clear_interrupt() noexcept;

} // namespace skybake
