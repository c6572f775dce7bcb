#pragma once
namespace pyrseg {
inline constexpr const char* kVersion = "0.1.0";
}
