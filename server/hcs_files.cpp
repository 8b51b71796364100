// `.hcs` files served exactly as they are on disk.
#include <fstream>

#include "server/model_sources.h"

namespace meshstream::server {

Result<CatalogModel> load_hcs_file(const ModelFile& file) {
  std::ifstream in(file.path, std::ios::binary | std::ios::ate);
  if (!in) return make_error(ErrorCode::kIo, file.path + ": cannot open it");
  const std::streamoff size = in.tellg();
  if (size <= 0) return make_error(ErrorCode::kInvalidArgument, file.path + ": empty file");
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(bytes.data()), size);
  // A file cut short while we read is caught by make_model's checks.
  bytes.resize(static_cast<size_t>(in.gcount()));
  if (bytes.empty()) return make_error(ErrorCode::kIo, file.path + ": cannot read it");
  return make_model(file.name, "hcs", file.path, own_bytes(std::move(bytes)));
}

}  // namespace meshstream::server
