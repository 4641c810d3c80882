#include "render_es/kms_probe.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace marionette::render {

namespace {
KmsMode describe_mode(const drmModeModeInfo& m) {
    KmsMode mode;
    mode.width = m.hdisplay;
    mode.height = m.vdisplay;
    const long long pixels = static_cast<long long>(m.htotal) * m.vtotal;
    mode.refresh_mhz = pixels > 0 ? static_cast<std::int32_t>(static_cast<long long>(m.clock) * 1000000LL / pixels)
                                  : static_cast<std::int32_t>(m.vrefresh) * 1000;
    mode.preferred = (m.type & DRM_MODE_TYPE_PREFERRED) != 0;
    return mode;
}

void read_connectors(int fd, KmsCardProbe& card) {
    drmModeRes* res = drmModeGetResources(fd);
    if (res == nullptr) {
        card.error = "not a KMS device (drmModeGetResources failed)";
        return;
    }
    for (int i = 0; i < res->count_connectors; ++i) {
        drmModeConnector* c = drmModeGetConnector(fd, res->connectors[i]);
        if (c == nullptr) continue;
        KmsConnector k;
        k.id = c->connector_id;
        const char* type = drmModeGetConnectorTypeName(c->connector_type);
        k.name = std::string(type != nullptr ? type : "Unknown") + "-" + std::to_string(c->connector_type_id);
        k.connected = c->connection == DRM_MODE_CONNECTED;
        for (int m = 0; m < c->count_modes; ++m) k.modes.push_back(describe_mode(c->modes[m]));
        card.connectors.push_back(std::move(k));
        drmModeFreeConnector(c);
    }
    drmModeFreeResources(res);
}
}  // namespace

std::vector<KmsCardProbe> probe_kms_cards(const KmsModeRequest& request, const std::string& dri_dir) {
    std::vector<KmsCardProbe> cards;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dri_dir, ec))
        if (entry.path().filename().string().rfind("card", 0) == 0) {
            KmsCardProbe card;
            card.path = entry.path().string();
            cards.push_back(std::move(card));
        }
    std::sort(cards.begin(), cards.end(), [](const KmsCardProbe& a, const KmsCardProbe& b) { return a.path < b.path; });
    for (KmsCardProbe& card : cards) {
        const int fd = ::open(card.path.c_str(), O_RDWR | O_CLOEXEC);
        if (fd < 0) {
            card.error = std::strerror(errno);
            continue;
        }
        card.opened = true;
        read_connectors(fd, card);
        ::close(fd);
        if (card.error.empty()) card.choice = choose_kms_mode(card.connectors, request);
    }
    return cards;
}

}  // namespace marionette::render
