#pragma once
// A read-only look at the DRM devices for `marionette doctor`: each
// /dev/dri/card*, whether it opens, its connectors and modes, and the connector
// and mode the KMS platform would choose (choose_kms_mode). Opens nothing for
// drawing and takes no DRM master, so it runs beside a compositor.
#include <string>
#include <vector>

#include "render_es/platform.hpp"

namespace marionette::render {

struct KmsCardProbe {
    std::string path;                     // /dev/dri/cardN
    bool opened = false;                  // open(O_RDWR) succeeded
    std::string error;                    // why it did not open, or is not a KMS device
    std::vector<KmsConnector> connectors;
    KmsChoice choice;                     // for the request given to probe_kms_cards
};

// Every /dev/dri/card* under `dri_dir`, in name order.
std::vector<KmsCardProbe> probe_kms_cards(const KmsModeRequest& request, const std::string& dri_dir = "/dev/dri");

}  // namespace marionette::render
