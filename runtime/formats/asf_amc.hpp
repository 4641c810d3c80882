#pragma once
// Acclaim ASF/AMC import (the CMU motion-capture database's format).
//
// Skeleton mapping: the ASF `root` becomes joint 0; every ASF bone becomes a joint
// of the same name located at the bone's *start* (its parent bone's end), so
// `lfemur` sits at the hip and `ltibia` at the knee, as in the CMU BVH conversions.
// The end of each leaf bone becomes an end site. Positions stay in the file's
// units (Clip::length_unit records `:units length`); angles honour `:units angle`.
#include <string>
#include <string_view>

#include "runtime/anim/clip.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette {

struct AsfSkeleton;  // parsed ASF, opaque to callers

struct AmcOptions {
    // AMC files carry no rate; CMU captured at 120 Hz.
    double frame_rate = 120.0;
};

// Parses ASF and AMC text (names used in errors). Throws ImportError with file,
// line and what was expected for malformed input in either file.
Clip import_asf_amc(std::string_view asf_text, const std::string& asf_name, std::string_view amc_text,
                    const std::string& amc_name, const AmcOptions& options = {});

// Reads both files; the clip is named after the AMC file without extension.
Clip load_asf_amc_files(const std::string& asf_path, const std::string& amc_path,
                        const AmcOptions& options = {});

// The skeleton alone (rest pose), for `clip info` on an .asf file.
Skeleton import_asf_skeleton(std::string_view asf_text, const std::string& asf_name);

}  // namespace marionette
