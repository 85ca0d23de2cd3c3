//! The ranks of a spatter run when it is started by `mpirun`.
//!
//! [`init`] looks at the environment a launcher (OpenMPI's `mpirun`, a PMI/PMIx launcher such as Slurm's
//! `srun`) gives each process. Started without one, the run is the ordinary one-rank run
//! ([`spatter_core::comm::SerialComm`]) and MPI is never initialised (a lone MPI start costs about half a
//! second and needs no launcher). Under a launcher, a build with the `mpi` feature initialises MPI and
//! returns an [`MpiComm`]; a build without it refuses to start with several ranks, because every copy
//! would run the whole scenario into the same folder.

use spatter_core::comm::{Comm, SerialComm};

#[cfg(feature = "mpi")]
mod world;
#[cfg(feature = "mpi")]
pub use world::MpiComm;

/// Environment variables a launcher sets to the number of ranks, in the order they are tried.
const SIZE_VARS: &[&str] = &["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "SLURM_NTASKS"];
/// Environment variables a launcher sets to this process's rank.
const RANK_VARS: &[&str] = &["OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK", "SLURM_PROCID"];

/// The world a run lives in, alive until the program ends (dropping it finalises MPI).
pub struct Launch {
    comm: Box<dyn Comm>,
    #[cfg(feature = "mpi")]
    _universe: Option<mpi::environment::Universe>,
}

impl Launch {
    /// This process's view of the ranks.
    pub fn comm(&self) -> &dyn Comm {
        self.comm.as_ref()
    }

    /// The one-rank world of an ordinary run.
    pub fn serial() -> Self {
        Launch {
            comm: Box::new(SerialComm),
            #[cfg(feature = "mpi")]
            _universe: None,
        }
    }
}

/// Why the ranks could not be set up; `rank` says which process reports it (print on rank 0 only).
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct LaunchError {
    pub rank: usize,
    pub message: String,
}

/// The number of ranks and this process's rank as a launcher announced them, if one did.
pub fn launcher_ranks() -> Option<(usize, usize)> {
    let read = |vars: &[&str]| vars.iter().find_map(|v| std::env::var(v).ok()?.trim().parse::<usize>().ok());
    let size = read(SIZE_VARS)?;
    Some((size, read(RANK_VARS).unwrap_or(0)))
}

/// True when this build can run on several ranks.
pub const fn has_mpi() -> bool {
    cfg!(feature = "mpi")
}

/// Sets up the world: MPI under a launcher (with the `mpi` feature), the one-rank world otherwise.
pub fn init() -> Result<Launch, LaunchError> {
    let Some((size, rank)) = launcher_ranks() else { return Ok(Launch::serial()) };
    #[cfg(feature = "mpi")]
    {
        let _ = size;
        world::init(rank)
    }
    #[cfg(not(feature = "mpi"))]
    {
        if size <= 1 {
            return Ok(Launch::serial());
        }
        Err(LaunchError {
            rank,
            message: format!(
                "this spatter was built without MPI, so its {size} copies under mpirun would each run the whole \
                 scenario into the same folder; build it with `cargo build --release --features mpi` (needs \
                 libopenmpi-dev and libclang-dev) or start it without mpirun"
            ),
        })
    }
}
