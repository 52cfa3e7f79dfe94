// Construction files: one constructed geometry on its own (the object a scene cell's
// "geometry" holds, e.g. {"revolve": {...}}; docs/SCENE.md, "Constructed geometry"), read by
// `trivox build` to make a volume and save it as a model file.
#pragma once

#include <atomic>
#include <filesystem>
#include <string_view>

#include "trivox/construct/report.h"

namespace trivox {

// Reads and builds the construction. Model files it names are read relative to its folder.
// Throws IoError when the file cannot be read and InputError ("file: /json/pointer: rule")
// for everything wrong in it. A volume that folds is not an error here: the report says so.
// `stop` (optional, may be set from a signal handler) is read by the long constructions
// (untangling), as read_scene reads it: once it is true, they throw CancelledError.
Constructed read_construction(const std::filesystem::path& path, const std::atomic<bool>* stop = nullptr);

// The same from text; `source` names it in errors and anchors relative file names.
Constructed parse_construction(std::string_view json_text, const std::filesystem::path& source,
                               const std::atomic<bool>* stop = nullptr);

}  // namespace trivox
