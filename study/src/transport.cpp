#include <cstdlib>

#include "feeddrive/study/spec.hpp"
#include "feeddrive/study/transport.hpp"

#ifdef FEEDDRIVE_STUDY_MPI
// The C API only: without these, Open MPI and MPICH pull in their deprecated C++ bindings.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace feeddrive::study {

std::string mpi_launcher() {
  // Open MPI's mpirun, PMIx (Open MPI 4+, srun --mpi=pmix), PMI-1/2 (srun --mpi=pmi2, MPICH).
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (const char* x = std::getenv(v)) return std::string(v) + "=" + x;
  return "";
}

#ifdef FEEDDRIVE_STUDY_MPI

namespace {

class MpiTransport final : public Transport {
 public:
  MpiTransport(int& argc, char**& argv) {
    int provided = 0;
    // Only the main thread of each rank calls MPI; the worker threads never do.
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    MPI_Comm local;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
    MPI_Comm_size(local, &local_size_);
    MPI_Comm_free(&local);
  }
  ~MpiTransport() override { MPI_Finalize(); }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  int local_size() const override { return local_size_; }
  void send(int to, int tag, const std::string& payload) override {
    MPI_Send(payload.data(), static_cast<int>(payload.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD);
  }
  std::optional<Message> poll() override {
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
    if (!flag) return std::nullopt;
    return take(st);
  }
  Message receive(int from) override {
    MPI_Status st;
    MPI_Probe(from, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
    return take(st);
  }
  int broadcast(int value) override {
    MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return value;
  }
  [[noreturn]] void abort(int code) override {
    MPI_Abort(MPI_COMM_WORLD, code);
    std::_Exit(code);
  }

 private:
  Message take(const MPI_Status& st) {
    int n = 0;
    MPI_Get_count(&st, MPI_BYTE, &n);
    Message m{st.MPI_SOURCE, st.MPI_TAG, std::string(static_cast<std::size_t>(n), '\0')};
    MPI_Recv(m.payload.data(), n, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return m;
  }
  int rank_{0}, size_{1}, local_size_{1};
};

}  // namespace

bool mpi_compiled() { return true; }

std::unique_ptr<Transport> connect(int& argc, char**& argv) {
  if (mpi_launcher().empty()) return nullptr;
  return std::make_unique<MpiTransport>(argc, argv);
}

#else

bool mpi_compiled() { return false; }

std::unique_ptr<Transport> connect(int&, char**&) {
  const std::string launcher = mpi_launcher();
  if (!launcher.empty())
    throw StudyError(
        "started by an MPI launcher (" + launcher +
        ") but this feeddrive-study was built without MPI (install libopenmpi-dev and rebuild; docs/deployment.md)");
  return nullptr;
}

#endif

}  // namespace feeddrive::study
