// Text seeds: calibration files in OpenCV FileStorage's three syntaxes, --intrinsics strings, command lines, and
// fuzz_py_arrays's byte choices.
#include <filesystem>

#include "tests/fuzz/seeds/seeds.hpp"

namespace fs = std::filesystem;

namespace pyrseg::fuzz {

namespace {

void calib_seeds(const fs::path& dir) {
    write_seed(dir, "matrix.xml",
               "<?xml version=\"1.0\"?>\n<opencv_storage>\n<camera_matrix type_id=\"opencv-matrix\">\n"
               "  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n"
               "  <data>525. 0. 319.5 0. 525. 239.5 0. 0. 1.</data></camera_matrix>\n</opencv_storage>\n");
    write_seed(dir, "map.xml",
               "<?xml version=\"1.0\"?>\n<opencv_storage>\n<fx>525.</fx>\n<fy>526.</fy>\n<cx>319.5</cx>\n"
               "<cy>239.5</cy>\n</opencv_storage>\n");
    write_seed(dir, "two_matrices.xml",
               "<?xml version=\"1.0\"?>\n<opencv_storage>\n<IR_intrinsic_params type_id=\"opencv-matrix\">\n"
               "  <rows>3</rows><cols>3</cols><dt>f</dt>\n  <data>571. 0. 320. 0. 571. 240. 0. 0. 1.</data>"
               "</IR_intrinsic_params>\n<RGB_intrinsic_params type_id=\"opencv-matrix\">\n"
               "  <rows>3</rows><cols>3</cols><dt>f</dt>\n  <data>525. 0. 319. 0. 525. 239. 0. 0. 1.</data>"
               "</RGB_intrinsic_params>\n</opencv_storage>\n");
    write_seed(dir, "matrix.yml",
               "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
               "   data: [ 525., 0., 319.5, 0., 525., 239.5, 0., 0., 1. ]\n");
    write_seed(dir, "map.yml",
               "%YAML:1.0\n---\ncamera_matrix:\n   fx: 525.\n   fy: 525.\n   cx: 319.5\n   cy: 239.5\n");
    write_seed(dir, "top_map.yml", "%YAML:1.0\nfx: 600\nfy: 601\ncx: 320\ncy: 240\n");
    write_seed(dir, "matrix.json",
               "{\n    \"camera_matrix\": {\n        \"type_id\": \"opencv-matrix\",\n        \"rows\": 3,\n"
               "        \"cols\": 3,\n        \"dt\": \"d\",\n"
               "        \"data\": [ 525.0, 0.0, 319.5, 0.0, 525.0, 239.5, 0.0, 0.0, 1.0 ]\n    }\n}\n");
    write_seed(dir, "map.json",
               "{\n    \"fx\": 525.0,\n    \"fy\": 525.0,\n    \"cx\": 319.5,\n    \"cy\": 239.5\n}\n");
}

void intrinsics_seeds(const fs::path& dir) {
    write_seed(dir, "kinect.txt", "525,525,319.5,239.5");
    write_seed(dir, "spaces.txt", " 1.5e3 , 1500 ,1031.5,771.5 ");
    write_seed(dir, "hex.txt", "0x1p9,5.25E2,-0,+239.5");
}

void args_seeds(const fs::path& dir) {
    write_seed(dir, "cloud.args", "scan.pcd\n--unit-mm\n1000\n--sensor\nkinect-v1\n--png\nout.png\n");
    write_seed(dir, "depth.args",
               "depth.png\n--intrinsics\n525,525,319.5,239.5\n--metres-per-unit=0.0002\n--metric=robust\n"
               "--normal-window\n3\n--curvature-stride\n4\n--dt-per-m2\n1.5\n--ct-growth\n0.1\n--edge-rounds\n2\n");
    write_seed(dir, "batch.args", "scans\n--out-dir\nout\n--write\nlabels,png,stats\n--progress\n1\n--sensor=auto\n");
    write_seed(dir, "params.args",
               "a.ply\n--ct\n0.3\n--dt=12.5\n--bridge-levels\n3\n--unjoinable-gap\n2\n--normal-radius\n4\n"
               "--no-label-edges\n--raw\n--depth-scale\n5000\n--calib\ncalib.yml:camera_matrix\n");
    write_seed(dir, "help.args", "--help\n");
}

// fuzz_py_arrays's inputs are FuzzedDataProvider's: the choices are read from the end (one byte each here: the
// operation last, then the array's kind, dtype, dimensions, strides, ...), buffer noise from the front. One seed per
// operation, for each of a few layouts: every choice 0 (a C-ordered array) or the byte given.
void py_arrays_seeds(const fs::path& dir) {
    // Choices in the order the harness reads them, written backwards (the last byte is read first).
    const auto seed = [&](const std::string& name, std::string choices) {
        const std::string noise = "\x00\x00\xc0\x7f\x00\x00\x80\x3f";
        std::string bytes(choices.rbegin(), choices.rend());
        write_seed(dir, name, noise + bytes);
    };
    for (int op = 0; op < 8; ++op) {
        const std::string o(1, char(op));
        // kind 0 (an array), dtype 0 (<f4), 3 dimensions of 4 x 5 x 3, natural strides.
        seed("op" + std::to_string(op) + "_f4_4x5x3", o + std::string("\x00\x00\x03\x04\x05\x03", 6));
        // dtype 4 (<u2), 2 dimensions of 6 x 7, the rows reversed.
        seed("op" + std::to_string(op) + "_u2_6x7", o + std::string("\x00\x04\x02\x06\x07\x03\x00", 7));
        // dtype 11 (|b1), 2 dimensions of 3 x 3, a zero stride.
        seed("op" + std::to_string(op) + "_b1_3x3", o + std::string("\x00\x0b\x02\x03\x03\x04\x00", 7));
    }
}

// fuzz_batch_plan's inputs are FuzzedDataProvider's too, read from the end: the number of inputs, then per input
// its pieces and whether it exists, then the output folder and the kinds. Three byte strings of small, medium and
// large batches to start from; libFuzzer's mutations find the colliding names.
void batch_plan_seeds(const fs::path& dir) {
    const auto seed = [&](const std::string& name, std::string choices) {
        write_seed(dir, name, std::string(choices.rbegin(), choices.rend()));
    };
    seed("one_npy", std::string("\x00\x01\x00\x00\x08\x01\x01\x01\x01", 9));
    seed("stem_collisions", std::string("\x02\x01\x00\x00\x08\x01\x01\x00\x0a\x01\x01\x00\x09\x00\x00\x03"
                                        "\x00\x01\x02\x03\x04\x05\x06",
                                        23));
    std::string every(1, '\x07');
    for (int i = 0; i < 8; ++i) every += std::string{'\x01', char(i), char(8 + i), char(i % 2)};
    every += std::string{'\x01', '\x08', 0, 1, 2, 3, 4, 5, 6, 7};
    seed("every_kind", every);
}

}  // namespace

void write_text_seeds(const fs::path& root) {
    calib_seeds(root / "fuzz_calib");
    intrinsics_seeds(root / "fuzz_intrinsics");
    args_seeds(root / "fuzz_args");
    py_arrays_seeds(root / "fuzz_py_arrays");
    batch_plan_seeds(root / "fuzz_batch_plan");
}

}  // namespace pyrseg::fuzz
