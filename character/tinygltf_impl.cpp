// The one translation unit that compiles tinygltf (Debian's libtinygltf-dev is
// header only). Images are never decoded: no stb_image, and gltf_character.cpp
// installs a loader that skips them (a character's textures are not drawn).
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include "character/tinygltf_config.hpp"
