// Machine descriptions (`model: type: multibody`): the description reader, its expressions and
// the Simbody model built from it.
#include "harness.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/machine_description.h"
#include "mbid/model/model_factory.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  mbid::fuzz::ExpectContractErrorsOnly([&] {
    const mbid::YamlReader root = mbid::YamlReader::FromString(text, "description.yaml");
    if (!root.IsMap() || !root.Has("model")) return;
    const mbid::YamlReader model = root.Child("model");
    if (model.IsMap() && model.Has("type") && model.String("type") == "multibody") {
      mbid::model::ReadMachineDescription(model).Validate();
    }
    mbid::model::MakeModel(model);
  });
  return 0;
}
