"""What generated robot packages import at run time. Never imports the compiler."""
