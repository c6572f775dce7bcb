#pragma once
// Controlled bridges between ground-truth objects, and plain connected-component labelling, for `pyrseg eval`
// (docs/quality.md).
//
// A bridge is a strip of fillable pixels across the edge band that separates two ground-truth objects in a
// fillable mask, joining the bodies of both: what a gap in thresholded edges does to a real mask.
// - The *core* of a ground-truth object is the largest 4-connected set of fillable pixels that all carry its
//   truth id (ties: the set with the smallest row-major first pixel).
// - Two objects are *neighbours* when a pixel of one core and a pixel of the other are at most max_gap pixels
//   apart in both x and y. Each pair of neighbours gets one bridge site: the pair of core pixels (p, q) at the
//   smallest Euclidean distance whose 4-connected digital path (below) crosses only pixels with data
//   (truth != 0); ties go to the smallest row-major index of p, then of q. No randomness: the sites depend only on
//   the ground truth and the mask.
// - The path from p to q is the 4-connected digital line that steps in x or y, whichever keeps it closer to the
//   straight segment (x first on a tie). A bridge of width w stamps a w x w square on every pixel of the path
//   (offsets -(w-1)/2 .. w/2 in x and y), making every stamped pixel with data fillable and valid. So the strip is
//   at least w pixels across in both the row and the column direction, and 4-connected.
#include <cstdint>
#include <vector>

namespace pyrseg::eval {

inline constexpr int kDefaultMaxGap = 10;

struct BridgeSite {
    std::uint32_t first = 0, second = 0;  // the two truth ids, first < second
    int x0 = 0, y0 = 0;                   // the core pixel of `first`
    int x1 = 0, y1 = 0;                   // the core pixel of `second`
};

// The bridge sites of a mask (fillable: W*H, non-zero = fillable; truth: W*H ground truth, 0 = no data), sorted by
// (first, second).
[[nodiscard]] std::vector<BridgeSite> find_bridge_sites(const std::vector<std::uint32_t>& truth,
                                                        const std::vector<std::uint8_t>& fillable, int width,
                                                        int height, int max_gap = kDefaultMaxGap);

// The pixels of the 4-connected digital path from (x0, y0) to (x1, y1), both included, as row-major indices.
[[nodiscard]] std::vector<std::size_t> digital_path(int x0, int y0, int x1, int y1, int width);

// Stamps a bridge of the given width (>= 1) at every site into fillable and valid (both W*H, set to 1).
void draw_bridges(const std::vector<BridgeSite>& sites, int bridge_width, const std::vector<std::uint32_t>& truth,
                  int width, int height, std::vector<std::uint8_t>& fillable, std::vector<std::uint8_t>& valid);

// Plain 4-connected components of the fillable pixels, labelled 1..count in row-major order of first pixel
// (0: not fillable).
[[nodiscard]] std::vector<std::uint32_t> connected_components(const std::vector<std::uint8_t>& fillable, int width,
                                                              int height, std::uint32_t* count = nullptr);

// The algorithm contract's step 6c on any labelling: each valid, non-fillable, unlabelled pixel takes the smallest
// label among its fillable, labelled 4-neighbours (it does not spread further). valid may be empty (all valid).
void label_edges(std::vector<std::uint32_t>& labels, const std::vector<std::uint8_t>& fillable,
                 const std::vector<std::uint8_t>& valid, int width, int height);

}  // namespace pyrseg::eval
