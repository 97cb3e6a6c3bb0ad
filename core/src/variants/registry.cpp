// SPDX-License-Identifier: MIT
// The one list of variants. Each variant file defines its VariantInfo; adding a variant is one
// file plus one line here.
#include <cstring>

#include "error.h"
#include "variant.h"

namespace ssao {

extern const VariantInfo kHorizonVariant;
extern const VariantInfo kHemisphereVariant;
extern const VariantInfo kSphereVariant;
extern const VariantInfo kVolumetricVariant;
extern const VariantInfo kUnsharpVariant;

const std::vector<VariantInfo>& variant_registry() {
  static const std::vector<VariantInfo> variants = {
      kHorizonVariant, kHemisphereVariant, kSphereVariant, kVolumetricVariant, kUnsharpVariant};
  return variants;
}

const VariantInfo& find_variant(const std::string& name) {
  for (const VariantInfo& v : variant_registry()) {
    if (name == v.name) return v;
  }
  throw_invalid_argument("unknown variant '" + name + "'");
}

Quality quality_of(const ParamValues& values) {
  const std::string& q = values.get_string("quality");
  if (q == "low") return Quality::low;
  if (q == "high") return Quality::high;
  if (q == "ultra") return Quality::ultra;
  return Quality::medium;
}

int count_or_preset(const ParamValues& values, const char* name, const int (&presets)[4]) {
  const int value = values.get_int(name);
  return value > 0 ? value : presets[int(quality_of(values))];
}

}  // namespace ssao
