// Authentication before the request is read: a gRPC AuthMetadataProcessor
// that refuses a call without a known bearer token (UNAUTHENTICATED) from its
// headers alone, so the server never parses a large message from a stranger.
// Roles are still checked by each handler (RequestContext::authorize).
// gRPC 1.51 accepts a processor on TLS credentials only; without TLS (loopback,
// --trusted-network) the token is checked by the handler, after the message
// (at most --max-message-mib) has been parsed. Health checks and reflection
// pass without a token.
#pragma once

#include <grpcpp/security/auth_metadata_processor.h>

#include "auth.h"

namespace hj::server {

class TokenGate final : public grpc::AuthMetadataProcessor {
 public:
  explicit TokenGate(const Authenticator& auth) : auth_(auth) {}

  // A map lookup: cheap enough for gRPC's own thread.
  bool IsBlocking() const override { return false; }
  grpc::Status Process(const InputMetadata& auth_metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed_auth_metadata, OutputMetadata* response_metadata) override;

 private:
  const Authenticator& auth_;
};

}  // namespace hj::server
