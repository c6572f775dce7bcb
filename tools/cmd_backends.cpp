#include <cstdio>

#include "pyrseg/backend.hpp"
#include "tools/args.hpp"
#include "tools/commands.hpp"

namespace pyrseg::cli {

int cmd_backends(const std::vector<std::string>& argv) {
    const Args args(argv, {}, {"help"});
    if (args.flag("help")) {
        std::puts(
            "Usage: pyrseg backends\n\n"
            "Lists every backend pyrseg knows, in the order 'auto' prefers them, whether it can run on this\n"
            "machine, its devices, and why not when it cannot. 'auto' takes the first available backend whose device\n"
            "is a GPU, else cpu: a GPU API running in software on the CPU (Mesa's lavapipe, PoCL's CPU device) is\n"
            "slower than the native cpu backend, so auto passes it by (it still runs when named).");
        return 0;
    }
    if (!args.positional().empty()) throw UsageError{"takes no arguments"};
    for (const BackendInfo& b : list_backends()) {
        std::printf("%-7s %s\n", b.name.c_str(),
                    !b.available ? "unavailable"
                                 : (b.emulated ? "available (a CPU emulation: auto passes it by)" : "available"));
        if (!b.available) std::printf("        %s\n", b.reason.c_str());
        for (const std::string& d : b.devices) std::printf("        device: %s\n", d.c_str());
    }
    const BackendChoice automatic = choose_backend("auto");
    std::printf("auto    %s (%s)\n", automatic.name.c_str(), automatic.reason.c_str());
    return 0;
}

}  // namespace pyrseg::cli
