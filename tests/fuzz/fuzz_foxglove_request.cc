// Fuzz target: a Foxglove client's text message to the live server
// (`--foxglove`): parsed into a subscribe or unsubscribe request, or refused
// with a reason; never anything else.

#include <cstdint>
#include <stdexcept>
#include <string>

#include "web/foxglove_protocol.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const sandbox::web::FoxgloveRequest request = sandbox::web::ParseFoxgloveRequest(text);
    using Op = sandbox::web::FoxgloveRequest::Op;
    if (request.op != Op::kSubscribe && !request.subscribe.empty()) std::abort();
    if (request.op != Op::kUnsubscribe && !request.unsubscribe.empty()) std::abort();
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).empty()) std::abort();  // a reason, always
  }
  return 0;
}
