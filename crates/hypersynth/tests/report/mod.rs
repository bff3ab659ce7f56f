mod games;
mod subtasks_export;
