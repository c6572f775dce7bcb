#pragma once
// The temporary files that exist while an output is being written (io::detail::write_atomically's, the CLI's
// staged outputs), in a table a signal handler can empty: Ctrl-C or a SIGTERM in the middle of a frame then leaves
// no hidden ".NAME.pyrseg-..." file beside the target. Registering allocates nothing and the removal is
// async-signal-safe (a fixed table of paths, unlink()). Only a program that owns its signals (the CLI) installs
// such a handler; the library never does.
#include <filesystem>

#include "pyrseg/io_export.hpp"

namespace pyrseg::io::detail {

// Registers `path` for as long as it lives (moved, the registration goes with it); it never removes the file
// itself. Paths over 4095 bytes, or more than 64 at once, are not registered (they are then left by a signal, as
// before). Exported (not installed), as the functions below: the pyrseg tool uses them, also against the shared
// libpyrseg_io, whose own writers register in the same table.
class PYRSEG_IO_EXPORT RegisteredTemporary {
public:
    RegisteredTemporary() = default;
    explicit RegisteredTemporary(const std::filesystem::path& path) noexcept;
    ~RegisteredTemporary();
    RegisteredTemporary(RegisteredTemporary&& other) noexcept;
    RegisteredTemporary& operator=(RegisteredTemporary&& other) noexcept;
    RegisteredTemporary(const RegisteredTemporary&) = delete;
    RegisteredTemporary& operator=(const RegisteredTemporary&) = delete;

private:
    int slot_ = -1;
};

// Removes every registered temporary file. Async-signal-safe: for a signal handler.
PYRSEG_IO_EXPORT void remove_registered_temporaries() noexcept;

// Installs handlers of SIGINT, SIGTERM, SIGHUP and SIGQUIT that remove the registered temporary files and then end
// the process by the same signal (its exit status as without the handler). For main() of a program.
PYRSEG_IO_EXPORT void remove_temporaries_on_termination_signals();

}  // namespace pyrseg::io::detail
