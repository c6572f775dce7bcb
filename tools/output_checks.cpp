#include "tools/output_checks.hpp"

#include <sys/stat.h>

#include <map>
#include <system_error>

#include "pyrseg/error.hpp"
#include "tools/args.hpp"
#include "tools/printable.hpp"

namespace pyrseg::cli {

namespace fs = std::filesystem;

namespace {

bool is_character_device(const fs::path& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

}  // namespace

std::string same_file_key(const fs::path& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) {
        return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
    }
    // Absolute first: weakly_canonical leaves a relative name none of whose parts exists as it is ("o.png"), but
    // makes "./o.png" absolute.
    std::error_code ec;
    const fs::path absolute = fs::absolute(path, ec).lexically_normal();
    fs::path resolved = fs::weakly_canonical(absolute, ec);
    if (ec) resolved = absolute;
    return "path " + resolved.lexically_normal().string();
}

void check_outputs(const std::vector<NamedOutput>& outputs) {
    std::map<std::string, const NamedOutput*> seen;
    for (const NamedOutput& o : outputs) {
        if (is_character_device(o.path)) continue;
        const auto [at, inserted] = seen.emplace(same_file_key(o.path), &o);
        if (!inserted) {
            const NamedOutput& first = *at->second;
            std::string message = first.option;
            message += " and ";
            message += o.option;
            message += " name the same file ";
            message += printable(o.path);
            if (first.path != o.path) {
                message += " (also spelt ";
                message += printable(first.path);
                message += ")";
            }
            message += ": one of them would be lost";
            throw UsageError{message};
        }
    }
    for (const NamedOutput& o : outputs) {
        std::error_code ec;
        if (fs::is_directory(o.path, ec)) {
            throw Error(ErrorCode::io, printable(o.path) + ": is a folder, not a file (" + o.option + ")");
        }
        const fs::path folder = o.path.parent_path();
        if (folder.empty() || fs::is_directory(folder, ec)) continue;
        throw Error(ErrorCode::io,
                    printable(o.path) + ": " +
                        (fs::exists(folder, ec) ? printable(folder) + " is a file, not a folder"
                                                : "the folder " + printable(folder) + " does not exist"));
    }
}

void make_output_folder(const std::string& folder) {
    if (folder.empty()) throw UsageError{"--out-dir needs a folder name (\".\" for this one)"};
    std::error_code ec;
    if (fs::exists(folder, ec) && !fs::is_directory(folder, ec)) {
        throw Error(ErrorCode::io, printable(fs::path(folder)) + ": is a file, not a folder (--out-dir)");
    }
    fs::create_directories(folder, ec);
    if (!fs::is_directory(folder)) {
        throw Error(ErrorCode::io, printable(fs::path(folder)) + ": cannot create the output folder" +
                                       (ec ? ": " + ec.message() : std::string()));
    }
}

}  // namespace pyrseg::cli
