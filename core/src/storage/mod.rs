//! Where a world keeps its state: the memory plan of its planes, the
//! header with the description and counters, and the shared-write view of
//! a plane that the tasks of a parallel step use.

pub(crate) mod cells;
pub(crate) mod layout;
pub(crate) mod world;
