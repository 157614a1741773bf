// An uploaded dataset (proto: UploadedDataset, session.json texts and frame
// files by relative path) turned into the library's Dataset. The files go
// into a private scratch folder and are read there by read_dataset(), so an
// upload is validated exactly as a dataset on disk is; the folder is removed
// before returning, and error messages name the file as the client sent it
// ("DATASET/SESSION/session.json: steps[3].cell: ...").
#pragma once

#include "calib/dataset.h"
#include "hapticjam/v1/calibration_service.pb.h"
#include "server_limits.h"

namespace hj::server {

// @throws ServiceError INVALID_ARGUMENT naming the session, file and key: no
//         session, a name or path that is not a plain relative one (absolute,
//         "..", repeated), more sessions or files than the limits allow, a
//         malformed session.json or frame, a frame session.json names but the
//         upload lacks, sessions of different devices.
Dataset dataset_from_upload(const hapticjam::v1::UploadedDataset& upload, const ServerLimits& limits);

}  // namespace hj::server
