//! Where a world keeps its state: the memory plan of its planes, the
//! header with the description and counters, the shared-write view of a
//! plane that the tasks of a parallel step use, and the plain data its
//! planes hold.

pub(crate) mod cells;
pub(crate) mod layout;
pub(crate) mod plain;
pub(crate) mod world;
