#include <rotorfit/base/input_error.h>
#include <rotorfit/base/run_control.h>

#include <deal.II/base/mpi.h>

#include <fcntl.h>
#include <linux/magic.h>
#include <sys/file.h>
#include <sys/vfs.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace rotorfit
{
  namespace run_control
  {
    namespace
    {
      volatile std::sig_atomic_t received = 0;
      int                        lock_fd  = -1;

      extern "C" void
      on_signal(const int s)
      {
        if (received != 0)
          {
            // a second signal: the user means it
            std::signal(s, SIG_DFL);
            std::raise(s);
          }
        received = s;
      }
    } // namespace

    void
    install_signal_handlers()
    {
      std::signal(SIGINT, on_signal);
      std::signal(SIGTERM, on_signal);
    }

    int
    pending_signal(const MPI_Comm comm)
    {
      return dealii::Utilities::MPI::max(static_cast<int>(received), comm);
    }

    std::string
    signal_name(const int s)
    {
      return s == SIGINT ? "SIGINT" : s == SIGTERM ? "SIGTERM" : "signal " + std::to_string(s);
    }

    void
    stop_if_interrupted(const MPI_Comm comm, const std::string &where)
    {
      const int s = pending_signal(comm);
      if (s != 0)
        throw Interrupted("interrupted by " + signal_name(s) + " " + where);
    }

    namespace
    {
      /// The refusal of a folder whose lock @p fd another run holds (closes @p fd).
      std::string
      in_use(const std::string &directory, const int fd)
      {
        char       buffer[32] = {};
        const auto n          = ::pread(fd, buffer, sizeof(buffer) - 1, 0);
        ::close(fd);
        const std::string pid = n > 0 ? std::string(buffer, n) : "unknown";
        return "Output/Directory = '" + directory +
               "' is in use by another rotorfit run (process id " +
               pid.substr(0, pid.find_first_of("\n ")) +
               "); wait for it to finish or choose another "
               "directory (two runs would interleave their rows).";
      }

      /// The name of a kernel pseudo file system, "" for any other.
      std::string
      pseudo_file_system(const std::string &path)
      {
        struct statfs fs;
        if (::statfs(path.c_str(), &fs) != 0)
          return "";
        switch (static_cast<unsigned long>(fs.f_type))
          {
            case PROC_SUPER_MAGIC:
              return "proc";
            case SYSFS_MAGIC:
              return "sysfs";
            case CGROUP_SUPER_MAGIC:
            case CGROUP2_SUPER_MAGIC:
              return "cgroup";
            case DEBUGFS_MAGIC:
              return "debugfs";
            case TRACEFS_MAGIC:
              return "tracefs";
            case SECURITYFS_MAGIC:
              return "securityfs";
            case DEVPTS_SUPER_MAGIC:
              return "devpts";
            case PSTOREFS_MAGIC:
              return "pstore";
            case BPF_FS_MAGIC:
              return "bpf";
            default:
              return "";
          }
      }
    } // namespace

    std::string
    check_writable(const std::string &directory)
    {
      namespace fs = std::filesystem;
      std::error_code ec;
      // the nearest existing ancestor decides whether it can be created
      fs::path existing = fs::path(directory).lexically_normal();
      while (!existing.empty() && !fs::exists(existing, ec))
        existing = existing.parent_path();
      if (existing.empty())
        existing = ".";
      if (!fs::is_directory(existing, ec))
        return "Output/Directory = '" + directory + "': '" + existing.string() +
               "' exists and is not a directory.";
      // /proc and /sys pass access() for root, then take no files
      const std::string pseudo = pseudo_file_system(existing.string());
      if (!pseudo.empty())
        return "Output/Directory = '" + directory + "': '" + existing.string() +
               "' lies on the kernel's " + pseudo +
               " file system, which holds no result files; choose a directory on a disk.";
      if (::access(existing.c_str(), W_OK | X_OK) != 0)
        return "Output/Directory = '" + directory + "': '" + existing.string() +
               "' is not writable (" + std::strerror(errno) +
               "); choose a directory you can write to.";
      // a folder another run holds: what lock_output_directory() would
      // refuse, found without creating anything. The shared lock is held
      // for a moment only (a run starting in that moment is refused too).
      const std::string lock = directory + "/.rotorfit.lock";
      const int         fd   = ::open(lock.c_str(), O_RDONLY | O_CLOEXEC);
      if (fd >= 0)
        {
          if (::flock(fd, LOCK_SH | LOCK_NB) != 0)
            return in_use(directory, fd);
          ::close(fd); // (releases the lock)
        }
      return "";
    }

    void
    lock_output_directory(const std::string &directory)
    {
      const std::string path = directory + "/.rotorfit.lock";
      const int         fd   = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
      if (fd < 0)
        throw InputError("Output/Directory = '" + directory + "': cannot write '" +
                         path + "' (" + std::strerror(errno) + ").");
      if (::flock(fd, LOCK_EX | LOCK_NB) != 0)
        throw InputError(in_use(directory, fd));
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) < 0)
        throw InputError("Output/Directory = '" + directory + "': cannot write '" +
                         path + "' (" + std::strerror(errno) + ").");
      lock_fd = fd; // held until the process ends
    }
  } // namespace run_control
} // namespace rotorfit
