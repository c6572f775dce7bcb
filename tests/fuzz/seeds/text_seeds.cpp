// Text seeds: calibration files in OpenCV FileStorage's three syntaxes, --intrinsics strings, and command lines.
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

}  // namespace

void write_text_seeds(const fs::path& root) {
    calib_seeds(root / "fuzz_calib");
    intrinsics_seeds(root / "fuzz_intrinsics");
    args_seeds(root / "fuzz_args");
}

}  // namespace pyrseg::fuzz
