#pragma once
// How the cases of one study are spread over the processes of an MPI job (Open MPI: mpirun,
// or srun under Slurm). Rank 0 owns the study: it loads and resolves it, keeps the queue of
// pending cases and the output folder; every other rank asks rank 0 for one case at a time, runs
// it and sends the outcome back (session.cpp). Rank 0 sends each rank the study's bases once
// (the base scenario's text and the controllers' blocks: StudyBases) and then each case's
// settings (CaseSettings, cases.hpp), from which the rank builds the case as a struct by the code
// rank 0 builds it with; the outcomes come back as JSON. The other ranks need no file of the
// study (the files its scenarios name, a plugin library, a waypoint table, they do need).
//
// MPI support is compiled in when CMake finds MPI (FEEDDRIVE_STUDY_MPI); MPI is initialised only
// when an MPI launcher started the process (its environment variables), so feeddrive-study
// always runs alone without one, with or without MPI installed.

#include <memory>
#include <optional>
#include <string>

namespace feeddrive::study {

enum Tag : int { kRequest = 1, kAssign = 2, kResult = 3, kBases = 4 };

struct Message {
  int from{0};
  int tag{0};
  std::string payload;
};

class Transport {
 public:
  virtual ~Transport() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// Ranks on this host (for the default number of threads per rank).
  virtual int local_size() const = 0;
  virtual void send(int to, int tag, const std::string& payload) = 0;
  /// A waiting message from any rank, without blocking.
  virtual std::optional<Message> poll() = 0;
  /// The next message from `from`, blocking.
  virtual Message receive(int from) = 0;
  /// Rank 0's `value` on every rank.
  virtual int broadcast(int value) = 0;
  /// Ends every rank of the job (a failure after the work was spread).
  [[noreturn]] virtual void abort(int code) = 0;
};

/// True if this build has MPI support.
bool mpi_compiled();
/// "NAME=VALUE" of the environment variable that shows an MPI launcher started this process
/// (OMPI_COMM_WORLD_SIZE, PMIX_RANK, PMI_RANK, ...), or "".
std::string mpi_launcher();
/// The MPI transport if an MPI launcher started this process; nullptr when it runs alone.
/// Throws StudyError if a launcher started it but MPI support is not compiled in.
std::unique_ptr<Transport> connect(int& argc, char**& argv);

}  // namespace feeddrive::study
