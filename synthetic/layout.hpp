#pragma once
// Where everything is: camera pose, floor, bin and the objects packed into it, in a world frame whose z is up and
// whose origin is on the floor under the middle of the view.
#include <vector>

#include "pyrseg/synthetic.hpp"
#include "solid.hpp"

namespace pyrseg::synthetic::detail {

struct Layout {
    Vec3 camera_position;
    Frame camera;               // camera axes in the world: x right, y down, z forward
    std::vector<Solid> solids;  // the floor (a plane), bin parts when there is a bin, then the objects by id
    int objects_placed = 0;
};

Layout make_layout(const SceneOptions& options);

}  // namespace pyrseg::synthetic::detail
