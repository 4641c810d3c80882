#include "app/config/character_config.hpp"

#include "character/gltf_character.hpp"

namespace marionette {

std::shared_ptr<const render::SkinnedMesh> load_render_character(const RenderConfig& config, const Skeleton& puppet) {
    if (config.character.empty()) return nullptr;
    retarget::RetargetMap map;
    map.origin = config.character_origin;
    map.roles = config.character_map;
    map.lines = config.character_map_lines;
    character::CharacterMesh loaded =
        character::load_gltf_character(config.character, puppet, config.character_map.empty() ? nullptr : &map);
    return std::make_shared<const render::SkinnedMesh>(std::move(loaded.mesh));
}

}  // namespace marionette
