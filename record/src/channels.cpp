#include "feeddrive/record/channels.hpp"

namespace feeddrive::record {

Channels::Channels(const std::string& prefix)
    : state(prefix + "_STATE"),
      command(prefix + "_CMD"),
      reference(prefix + "_REF"),
      status(prefix + "_STATUS"),
      resend(prefix + "_RESEND"),
      summary(prefix + "_SUMMARY"),
      info(prefix + "_INFO") {}

}  // namespace feeddrive::record
