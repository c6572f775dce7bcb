// A consumer of the installed pyrseg::io: a synthetic frame written as PCD and read back must segment exactly as the
// frame itself, and a failure must arrive as a pyrseg::Error that the application can catch (across the shared
// libraries' boundary, where the exception's type information must be exported).
#include <pyrseg/io.hpp>
#include <pyrseg/pyrseg.hpp>
#include <pyrseg/synthetic.hpp>

#include <cstdio>
#include <filesystem>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: io_consumer SCRATCH_DIR\n");
        return 2;
    }
    pyrseg::synthetic::SceneOptions options;
    options.width = 160;
    options.height = 120;
    const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(options);

    pyrseg::io::PointCloud cloud;
    cloud.width = scene.width;
    cloud.height = scene.height;
    cloud.points = scene.points;
    const std::filesystem::path path = std::filesystem::path(argv[1]) / "frame.pcd";
    pyrseg::io::write_pcd(path, cloud, pyrseg::io::PcdEncoding::binary_compressed);
    const pyrseg::io::PointCloud read = pyrseg::io::read_pcd(path);

    pyrseg::Segmenter segmenter(scene.width, scene.height, {}, "cpu");
    pyrseg::CloudView view;
    view.width = scene.width;
    view.height = scene.height;
    view.points = scene.points.data();
    const pyrseg::Result direct = segmenter.segment(view);
    view.points = read.points.data();
    const pyrseg::Result from_file = segmenter.segment(view);
    if (direct.labels != from_file.labels || direct.segment_count == 0) {
        std::fprintf(stderr, "io: the frame read back segments differently (%u vs %u segments)\n", direct.segment_count,
                     from_file.segment_count);
        return 1;
    }

    try {
        (void)pyrseg::io::read_pcd(std::filesystem::path(argv[1]) / "missing.pcd");
        std::fprintf(stderr, "io: reading a missing file did not throw\n");
        return 1;
    } catch (const pyrseg::Error& error) {
        if (error.code() != pyrseg::ErrorCode::io) {
            std::fprintf(stderr, "io: a missing file gave %s, not io\n", pyrseg::to_string(error.code()));
            return 1;
        }
    }
    std::printf("io: %u segments, the same after a PCD round trip; pyrseg %s\n", from_file.segment_count,
                pyrseg::kVersion);
    return 0;
}
