//! CiA 402, drive profiles, PDO images, simulated drives and bus backends.
